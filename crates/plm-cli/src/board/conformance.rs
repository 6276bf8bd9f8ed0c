//! `plm board conformance NODE`: one board against the board protocol
//! (docs/board-protocol.md, version 1), rule by rule, each passed, failed
//! or not checked, in words. Every frame is plm-core's; this only sends
//! them through the [`Driver`] and judges the answers.
//!
//! Nothing it sends can change what the board runs: the one campaign it
//! opens never gets its last segment, its swap is refused for that, and
//! it is aborted at the end.

mod rfu;

use super::driver::Driver;
use super::{exit, session, Failure};
use plm_core::app::discovery::rounds::ROUND_MARGIN;
use plm_core::app::rfu::{Status, REASONS, STATES};
use plm_core::app::update::UpdateConfig;
use plm_core::app::{Address, AppEvent, ErrorCode, Happening, Message, Release, Request, Service};
use plm_core::time::{Duration, Instant, MS};
use rfu::CAMPAIGN;
use serde_json::json;

/// The rules, in the order they are checked: name, and what a board
/// must do, in words (docs/board-protocol.md, "Conformance").
pub const RULES: &[(&str, &str)] = &[
    (
        "release",
        "answers SERVICE_FW_REL_GET (06h) with [firmware x, y, stack x, y]",
    ),
    (
        "error-frame",
        "answers a service request it refuses with APP_ERROR_FRAME 0004h",
    ),
    (
        "discovery",
        "answers a unicast SERVICE_NET_DISCOVER_REQ (0Bh) within its window",
    ),
    (
        "discovery-ack",
        "keeps quiet for the rest of a discovery session once acknowledged",
    ),
    (
        "status",
        "answers RFU_STATUS_GET (11h) with the 85-byte status",
    ),
    (
        "header",
        "acknowledges SERVICE_RFU_SET_IMG_HEADER (0Ch) and opens the campaign",
    ),
    (
        "bitmap",
        "takes SERVICE_RFU_SET_IMG_DATA (0Dh) without answer; the status names the segments held",
    ),
    (
        "swap",
        "refuses SERVICE_RFU_SWAP_IMG (0Eh) while a segment is missing",
    ),
    (
        "abort",
        "acknowledges RFU_ABORT (12h), forgets the campaign, runs what it ran",
    ),
];

/// The discovery window it asks for, seconds.
const WINDOW: u8 = 1;

/// How a rule came out.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// Kept, and what was seen.
    Passed(String),
    /// Broken, and how.
    Failed(String),
    /// Could not be checked, and why.
    NotChecked(String),
}

/// What one request brought: the answer (or why none), and frames from
/// the board that fit no layout meanwhile.
struct Got {
    answer: Result<Message, String>,
    malformed: Vec<String>,
    rtt: Duration,
}

impl Got {
    /// Why the answer is not `want`, in words.
    fn not(&self, want: &str) -> String {
        let mut words = match &self.answer {
            Ok(Message::Error(code)) => {
                format!("answered with an error frame, {code}, where {want} was due")
            }
            Ok(other) => format!("answered {} where {want} was due", other.name()),
            Err(why) => format!("{why} ({want} was due)"),
        };
        if let Some(first) = self.malformed.first() {
            let times = self.malformed.len();
            let again = if times > 1 {
                format!(", {times} times")
            } else {
                String::new()
            };
            words = format!("sent a frame that does not fit the layout ({first}{again}); {words}");
        }
        words
    }

    fn ms(&self) -> u64 {
        self.rtt / MS
    }
}

/// What the board sent unasked while the check listened.
enum Heard {
    Frame(Message),
    Malformed(String),
}

struct Check<'a> {
    d: &'a mut Driver,
    node: Address,
    json: bool,
    verdicts: Vec<(&'static str, Verdict)>,
}

impl Check<'_> {
    /// Sends `m` to the board through the requester and waits for its
    /// fate.
    fn ask(&mut self, m: Message) -> Result<Got, Failure> {
        let id = self.d.submit(Request::to(self.node, m))?;
        let mut malformed = Vec::new();
        loop {
            for h in self.d.step(None)? {
                let Happening::App(e) = h else { continue };
                match e {
                    AppEvent::Malformed { address, error } if address == self.node => {
                        malformed.push(error.to_string())
                    }
                    e if e.fate_of() == Some(id) => {
                        let (answer, rtt) = match e {
                            AppEvent::Answered { answer, rtt, .. } => (Ok(answer), rtt),
                            AppEvent::Failed { reason, .. } => (Err(reason), 0),
                            _ => (Err("sent, no answer expected".into()), 0),
                        };
                        return Ok(Got {
                            answer,
                            malformed,
                            rtt,
                        });
                    }
                    _ => {}
                }
            }
        }
    }

    /// Sends `m` to the board as a frame that waits for nothing.
    fn send(&mut self, m: &Message) -> Result<(), Failure> {
        self.d.send(m.to(self.node))
    }

    /// What the board sends unasked for `wait`, or until `enough` says
    /// so; with when each came.
    fn listen(
        &mut self,
        wait: Duration,
        enough: impl Fn(&Heard) -> bool,
    ) -> Result<Vec<(Instant, Heard)>, Failure> {
        let until = self.d.now() + wait;
        let mut heard = Vec::new();
        while self.d.now() < until {
            for h in self.d.step(Some(until))? {
                let got = match h {
                    Happening::App(AppEvent::Unsolicited {
                        address, message, ..
                    }) if address == self.node => Heard::Frame(message),
                    Happening::App(AppEvent::Malformed { address, error })
                        if address == self.node =>
                    {
                        Heard::Malformed(error.to_string())
                    }
                    _ => continue,
                };
                let stop = enough(&got);
                heard.push((self.d.now(), got));
                if stop {
                    return Ok(heard);
                }
            }
        }
        Ok(heard)
    }

    /// The status, or why there is none in words.
    fn status(&mut self) -> Result<Result<Status, String>, Failure> {
        let got = self.ask(Message::Service(Service::RfuStatusGet {
            campaign: CAMPAIGN,
        }))?;
        Ok(match &got.answer {
            Ok(Message::Service(Service::RfuStatus(s))) => Ok(s.clone()),
            _ => Err(got.not("the RFU_STATUS_GET reply")),
        })
    }

    fn say(&mut self, rule: &'static str, v: Verdict) {
        let what = RULES.iter().find(|r| r.0 == rule).map_or("", |r| r.1);
        let (tag, result, words) = match &v {
            Verdict::Passed(w) => ("pass", "passed", w),
            Verdict::Failed(w) => ("FAIL", "failed", w),
            Verdict::NotChecked(w) => ("skip", "not checked", w),
        };
        if self.json {
            say!(
                "{}",
                json!({"rule": rule, "what": what, "result": result, "words": words})
            );
        } else {
            say!("{tag}  {rule:<14}{what}: {words}");
        }
        self.verdicts.push((rule, v));
    }
}

/// Words for a status.
fn status_words(s: &Status) -> String {
    format!(
        "campaign {}, {}, reason {}, {} segment(s) held",
        s.campaign,
        s.state().map_or("?", |st| st.name()),
        s.reason().map_or("?", |r| REASONS[r.byte() as usize]),
        s.received
    )
}

/// Runs every rule against `node`; prints each verdict as it comes.
pub fn run(d: &mut Driver, node: Address, json: bool) -> Result<u8, Failure> {
    tell!(
        "plm board: checking {node} against the board protocol, version 1 \
         (docs/board-protocol.md); about 10 s"
    );
    let mut c = Check {
        d,
        node,
        json,
        verdicts: Vec::new(),
    };
    let release = release(&mut c)?;
    error_frame(&mut c)?;
    discovery(&mut c, release)?;
    let status = status(&mut c)?;
    rfu::rules(&mut c, status, release)?;

    let count = |f: fn(&Verdict) -> bool| c.verdicts.iter().filter(|(_, v)| f(v)).count();
    let passed = count(|v| matches!(v, Verdict::Passed(_)));
    let failed = count(|v| matches!(v, Verdict::Failed(_)));
    let unchecked = count(|v| matches!(v, Verdict::NotChecked(_)));
    tell!(
        "plm board: {node}: {passed} of {} rules passed, {failed} failed, {unchecked} not checked",
        c.verdicts.len()
    );
    Ok(if passed == c.verdicts.len() {
        exit::OK
    } else {
        exit::FAILED
    })
}

/// `release`: 06h, whose answer every later rule compares with.
fn release(c: &mut Check) -> Result<Option<Release>, Failure> {
    let got = c.ask(Message::Service(Service::FwRelGet))?;
    Ok(match &got.answer {
        Ok(Message::Service(Service::FwRel { firmware, stack })) => {
            let words = format!("firmware {firmware}, stack {stack}, in {} ms", got.ms());
            c.say("release", Verdict::Passed(words));
            Some(*firmware)
        }
        _ => {
            let words = got.not("the SERVICE_FW_REL_GET reply");
            c.say("release", Verdict::Failed(words));
            None
        }
    })
}

/// `error-frame`: 06h with a data byte (it takes none), and a user
/// command no board knows (7Fh).
fn error_frame(c: &mut Check) -> Result<(), Failure> {
    let refused = Message::Error(ErrorCode::SERVICE_CMD_ERROR);
    let bad = Message::Service(Service::Raw {
        command: 0x06,
        data: vec![0],
    });
    let got = c.ask(bad)?;
    if got.answer.as_ref() != Ok(&refused) {
        let words = format!(
            "SERVICE_FW_REL_GET with a data byte (it takes none): {}",
            got.not("APP_ERROR_SERVICE_CMD_ERROR")
        );
        c.say("error-frame", Verdict::Failed(words));
        return Ok(());
    }
    let unknown = Message::Service(Service::Raw {
        command: 0x7f,
        data: Vec::new(),
    });
    c.send(&unknown)?;
    let heard = c.listen(UpdateConfig::default().gap + 1_500 * MS, |h| {
        matches!(h, Heard::Frame(_))
    })?;
    let verdict = match heard.iter().find_map(|(_, h)| match h {
        Heard::Frame(m) => Some(m),
        Heard::Malformed(_) => None,
    }) {
        Some(m) if *m == refused => Verdict::Passed(format!(
            "a malformed SERVICE_FW_REL_GET (in {} ms) and the unknown user command 7Fh \
             were each answered with APP_ERROR_SERVICE_CMD_ERROR",
            got.ms()
        )),
        Some(m) => Verdict::Failed(format!(
            "the unknown user command 7Fh was answered with {}, not the error frame",
            m.name()
        )),
        None => Verdict::Failed(
            "the unknown user command 7Fh was not answered: a refused request gets the \
             error frame"
                .into(),
        ),
    };
    c.say("error-frame", verdict);
    Ok(())
}

/// Sends a unicast discovery of `session`; the reply heard within the
/// window and its margin, and when, in ms after the request.
fn discover(
    c: &mut Check,
    session: u8,
) -> Result<Option<(plm_core::app::Discovered, u64)>, Failure> {
    let sent = c.d.now();
    c.send(&Message::Service(Service::Discover {
        session,
        window: WINDOW,
    }))?;
    let wait = WINDOW as u64 * 1_000 * MS + ROUND_MARGIN;
    let heard = c.listen(wait, |h| {
        matches!(h, Heard::Frame(Message::Service(Service::DiscoverReply(_))))
    })?;
    Ok(heard.iter().find_map(|(at, h)| match h {
        Heard::Frame(Message::Service(Service::DiscoverReply(r))) => Some((*r, (at - sent) / MS)),
        _ => None,
    }))
}

/// `discovery` and `discovery-ack` (docs/board-protocol.md, "Discovery").
fn discovery(c: &mut Check, release: Option<Release>) -> Result<(), Failure> {
    let first = session();
    let ack = Message::Service(Service::Discover {
        session: first,
        window: WINDOW,
    })
    .ack();
    let verdict = match discover(c, first)? {
        None => Verdict::Failed(format!(
            "no answer to a unicast request (session {first}, window {WINDOW} s) within {} ms",
            (WINDOW as u64 * 1_000 * MS + ROUND_MARGIN) / MS
        )),
        Some((r, _)) if release.is_some_and(|v| v != r.firmware) => Verdict::Failed(format!(
            "it says firmware {} where SERVICE_FW_REL_GET says {}",
            r.firmware,
            release.unwrap_or_default()
        )),
        Some((r, _)) if r.snr > plm_core::app::service::SNR_MAX => Verdict::Failed(format!(
            "SNR {} is outside 0-{}",
            r.snr,
            plm_core::app::service::SNR_MAX
        )),
        Some((r, ms)) => Verdict::Passed(format!(
            "firmware {}, stack {}, SNR {} dB, {ms} ms after the request",
            r.firmware, r.stack, r.snr
        )),
    };
    let found = matches!(verdict, Verdict::Passed(_));
    c.say("discovery", verdict);
    if !found {
        c.say(
            "discovery-ack",
            Verdict::NotChecked("the board does not answer a discovery".into()),
        );
        return Ok(());
    }
    c.send(&ack)?;
    let again = discover(c, first)?;
    let next = first % 255 + 1;
    let verdict = match again {
        Some((_, ms)) => Verdict::Failed(format!(
            "acknowledged ([01h, 0Bh]) in session {first}, it answered that session again \
             {ms} ms after the next request"
        )),
        None => match discover(c, next)? {
            None => Verdict::Failed(format!(
                "quiet in session {first} once acknowledged, but no answer in the new session {next}"
            )),
            Some(_) => Verdict::Passed(format!(
                "quiet in session {first} once acknowledged; answered again in session {next}"
            )),
        },
    };
    // Leaves it quiet in the last session, as a discovery would.
    let last = Message::Service(Service::Discover {
        session: next,
        window: WINDOW,
    });
    c.send(&last.ack())?;
    c.say("discovery-ack", verdict);
    Ok(())
}

/// `status`: 11h before the campaign; the status it gives.
fn status(c: &mut Check) -> Result<Option<Status>, Failure> {
    Ok(match c.status()? {
        Err(why) => {
            c.say("status", Verdict::Failed(why));
            None
        }
        Ok(s) => {
            let held = s.bitmap.iter().map(|b| b.count_ones()).sum::<u32>();
            let verdict = if s.state().is_none() {
                Verdict::Failed(format!(
                    "state {} is none of {}",
                    s.state,
                    STATES.join(", ")
                ))
            } else if s.reason().is_none() {
                Verdict::Failed(format!(
                    "reason {} is none of {}",
                    s.reason,
                    REASONS.join(", ")
                ))
            } else if held != s.received as u32 {
                Verdict::Failed(format!(
                    "it says {} segment(s) held and its bitmap has {held} bit(s) set",
                    s.received
                ))
            } else {
                Verdict::Passed(status_words(&s))
            };
            let ok = matches!(verdict, Verdict::Passed(_));
            c.say("status", verdict);
            ok.then_some(s)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every rule is described in the specification, under its name.
    #[test]
    fn every_rule_is_in_the_specification() {
        let spec = include_str!("../../../../docs/board-protocol.md");
        for (name, _) in RULES {
            assert!(
                spec.contains(&format!("| `{name}` |")),
                "docs/board-protocol.md has no row for the rule `{name}`"
            );
        }
    }

    /// A simulated board breaks each rule under its own name.
    #[test]
    fn every_rule_can_be_broken_on_plm_sim() {
        let names: Vec<&str> = RULES.iter().map(|r| r.0).collect();
        let breaches: Vec<&str> = plm_sim::breach::BREACHES.iter().map(|b| b.0).collect();
        assert_eq!(names, breaches);
    }

    #[test]
    fn the_image_is_three_segments_and_never_whole_on_a_board() {
        let image = rfu::image();
        assert_eq!(plm_core::app::rfu::segments(image.len()), 3);
        assert_eq!(plm_core::app::rfu::segment_of(&image, 2).len(), 8);
    }
}
