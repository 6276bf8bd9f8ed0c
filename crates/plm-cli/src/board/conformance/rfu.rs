//! The RFU rules of `plm board conformance`: `header`, `bitmap`, `swap`
//! and `abort`, on one campaign that never gets its last segment, so that
//! the board never holds a whole image to swap to; aborted at the end.

use super::{status_words, Check, Heard, Verdict};
use crate::board::Failure;
use plm_core::app::rfu::{self, Header, RfuReason, RfuState, Status, REASONS};
use plm_core::app::update::UpdateConfig;
use plm_core::app::{ErrorCode, FrameType, Message, Release, Service};
use plm_core::time::{Duration, MS};

/// The campaign the check opens and aborts.
pub const CAMPAIGN: u8 = 254;
/// Bytes of the image it announces: three segments, the last short. Its
/// last segment is never sent.
pub const IMAGE_LEN: usize = 2 * rfu::SEGMENT + 8;
/// How long it listens for what must not come (an answer to a segment).
const QUIET: Duration = 500 * MS;

/// The image the check announces: an STM32F10x stack pointer and reset
/// vector into slot 0, then a pattern. It never gets whole on a board.
pub fn image() -> Vec<u8> {
    let mut b: Vec<u8> = (0..IMAGE_LEN).map(|i| (i * 7 + 3) as u8).collect();
    b[..4].copy_from_slice(&0x2000_5000u32.to_le_bytes());
    b[4..8].copy_from_slice(&(rfu::image::LINK_BASE + 0x101).to_le_bytes());
    b
}

/// `header`, `bitmap`, `swap` and `abort`: one campaign that never gets
/// its last segment, aborted at the end.
pub(super) fn rules(
    c: &mut Check,
    before: Option<Status>,
    release: Option<Release>,
) -> Result<(), Failure> {
    let rest = ["header", "bitmap", "swap", "abort"];
    let busy = before.as_ref().and_then(|s| match s.state() {
        Some(RfuState::Receiving | RfuState::Complete) if s.campaign != CAMPAIGN => Some(format!(
            "the board holds campaign {} ({}): finish it or abort it, then run again",
            s.campaign,
            s.state().map_or("?", |st| st.name())
        )),
        Some(RfuState::Trial) => {
            Some("the board's last update runs on trial: wait for it to confirm itself".into())
        }
        _ => None,
    });
    if let Some(why) = busy {
        for r in rest {
            c.say(r, Verdict::NotChecked(why.clone()));
        }
        return Ok(());
    }
    let status_ok = before.is_some();
    let image = image();
    let header = Header::of(CAMPAIGN, Release::default(), &image);

    // header
    let got = c.ask(Message::Service(Service::RfuHeader(header)))?;
    let acked = got.answer
        == Ok(Message::Ack {
            frame_type: FrameType::Service,
            echo: 0x0c,
        });
    let verdict = if !acked {
        Verdict::Failed(got.not("the ACK [01h, 0Ch]"))
    } else if !status_ok {
        Verdict::Passed(format!(
            "acknowledged in {} ms (its status could not be read)",
            got.ms()
        ))
    } else {
        match c.status()? {
            Ok(s)
                if s.campaign == CAMPAIGN
                    && s.state() == Some(RfuState::Receiving)
                    && s.received == 0 =>
            {
                Verdict::Passed(format!(
                    "acknowledged in {} ms; status {}",
                    got.ms(),
                    status_words(&s)
                ))
            }
            Ok(s) => Verdict::Failed(format!(
                "acknowledged, but the status says {} where campaign {CAMPAIGN}, RECEIVING, 0 held was due",
                status_words(&s)
            )),
            Err(why) => Verdict::Failed(format!("acknowledged; then its status: {why}")),
        }
    };
    c.say("header", verdict);
    if !acked {
        // Whatever it made of the header, it forgets it.
        c.send(&Message::Service(Service::RfuAbort { campaign: CAMPAIGN }))?;
        for r in &rest[1..] {
            c.say(
                r,
                Verdict::NotChecked("the board did not take the header".into()),
            );
        }
        return Ok(());
    }

    // bitmap: segments 0 and 1 of the campaign, the last of another.
    let count = header.segments();
    let gap = UpdateConfig::default().gap;
    let mut heard = Vec::new();
    for (campaign, n) in [(CAMPAIGN, 0), (CAMPAIGN, 1), (CAMPAIGN - 1, count - 1)] {
        let data = rfu::segment_of(&image, n).to_vec();
        c.send(&Message::Service(Service::RfuData {
            campaign,
            segment: n as u16,
            data,
        }))?;
        heard.extend(c.listen(gap, |_| false)?);
    }
    heard.extend(c.listen(QUIET, |_| false)?);
    let answered: Vec<String> = heard
        .iter()
        .map(|(_, h)| match h {
            Heard::Frame(m) => m.name().to_string(),
            Heard::Malformed(why) => format!("a frame that does not fit ({why})"),
        })
        .collect();
    let verdict = if !answered.is_empty() {
        Verdict::Failed(format!(
            "segments have no answer; it sent {}",
            answered.join(", ")
        ))
    } else if !status_ok {
        Verdict::NotChecked("segments unanswered, as due; its status could not be read".into())
    } else {
        match c.status()? {
            Err(why) => Verdict::Failed(format!("its status: {why}")),
            Ok(s) => {
                let held: Vec<usize> = (0..count).filter(|&i| s.has(i)).collect();
                let extra = s.bitmap.iter().skip(1).any(|b| *b != 0);
                if held != [0, 1] || extra || s.bitmap[0] & !0b11 != 0 {
                    let set: Vec<String> = (0..rfu::SEGMENTS_MAX)
                        .filter(|&i| s.has(i))
                        .map(|i| i.to_string())
                        .collect();
                    Verdict::Failed(format!(
                        "sent segments 0 and 1 (and segment {} of campaign {}, to be ignored); \
                         the bitmap names [{}]: bit i % 8 of byte i / 8, from bit 0, is segment i",
                        count - 1,
                        CAMPAIGN - 1,
                        set.join(", ")
                    ))
                } else if s.received != 2 || s.state() != Some(RfuState::Receiving) {
                    Verdict::Failed(format!(
                        "after segments 0 and 1 of {count}: {}",
                        status_words(&s)
                    ))
                } else if s.reason() != Some(RfuReason::OtherCampaign) {
                    Verdict::Failed(format!(
                        "a segment of campaign {} was ignored but not reported: reason {} where \
                         OTHER_CAMPAIGN was due",
                        CAMPAIGN - 1,
                        s.reason().map_or("?", |r| REASONS[r.byte() as usize])
                    ))
                } else {
                    Verdict::Passed(format!(
                        "no answer to segments; status {}: segments 0 and 1, the other \
                         campaign's segment ignored and reported",
                        status_words(&s)
                    ))
                }
            }
        }
    };
    c.say("bitmap", verdict);

    // swap, the last segment missing.
    let got = c.ask(Message::Service(Service::RfuSwap {
        campaign: CAMPAIGN,
        crc: header.crc,
    }))?;
    let refused = got.answer == Ok(Message::Error(ErrorCode::SERVICE_CMD_ERROR));
    let verdict = if let Ok(Message::Ack { .. }) = got.answer {
        Verdict::Failed(format!(
            "acknowledged a swap with segment {} missing: it must refuse it with \
             APP_ERROR_SERVICE_CMD_ERROR and say SEGMENTS_MISSING",
            count - 1
        ))
    } else if !refused {
        Verdict::Failed(got.not("APP_ERROR_SERVICE_CMD_ERROR"))
    } else if !status_ok {
        Verdict::Passed(format!(
            "refused in {} ms (its status could not be read)",
            got.ms()
        ))
    } else {
        match c.status()? {
            Ok(s) if s.reason() == Some(RfuReason::Missing) => Verdict::Passed(format!(
                "refused with APP_ERROR_SERVICE_CMD_ERROR in {} ms; status {}",
                got.ms(),
                status_words(&s)
            )),
            Ok(s) => Verdict::Failed(format!(
                "refused, but the status says {} where SEGMENTS_MISSING was due",
                status_words(&s)
            )),
            Err(why) => Verdict::Failed(format!("refused; then its status: {why}")),
        }
    };
    c.say("swap", verdict);

    // abort: the campaign forgotten, the same firmware running.
    let got = c.ask(Message::Service(Service::RfuAbort { campaign: CAMPAIGN }))?;
    let acked = got.answer
        == Ok(Message::Ack {
            frame_type: FrameType::Service,
            echo: rfu::RFU_ABORT,
        });
    let verdict = if !acked {
        Verdict::Failed(got.not("the ACK [01h, 12h]"))
    } else {
        let after = if status_ok { Some(c.status()?) } else { None };
        let now = c.ask(Message::Service(Service::FwRelGet))?;
        let running = match &now.answer {
            Ok(Message::Service(Service::FwRel { firmware, .. })) => Some(*firmware),
            _ => None,
        };
        match after {
            Some(Err(why)) => Verdict::Failed(format!("acknowledged; then its status: {why}")),
            Some(Ok(s))
                if matches!(s.state(), Some(RfuState::Receiving | RfuState::Complete))
                    || s.reason() != Some(RfuReason::Aborted) =>
            {
                Verdict::Failed(format!(
                    "acknowledged, but the status says {} where the campaign forgotten, \
                     reason ABORTED was due",
                    status_words(&s)
                ))
            }
            _ if release.is_some() && running != release => Verdict::Failed(format!(
                "acknowledged, but it now runs {} where it ran {} before",
                running.map_or("nothing that answers 06h".into(), |r| r.to_string()),
                release.unwrap_or_default()
            )),
            after => Verdict::Passed(format!(
                "acknowledged in {} ms{}; it still runs {}",
                got.ms(),
                match after {
                    Some(Ok(s)) => format!("; status {}", status_words(&s)),
                    _ => String::new(),
                },
                running.map_or("?".into(), |r| r.to_string())
            )),
        }
    };
    c.say("abort", verdict);
    Ok(())
}
