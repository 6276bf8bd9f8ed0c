//! The traffic log behind the inspector: every element both ways as
//! plm-core decoded it, in a bounded buffer that counts what it dropped,
//! with filters and JSON Lines export and import.
//!
//! A line of the export is exactly what `plm decode` prints for the
//! element, with the time it was seen first: `{"time_us":…, "kind":…}`.
//! Readers of `plm decode` output ignore the extra key, and the import
//! takes `plm decode` output as it is (elements without a time).

use plm_core::decode::Decoded;
use plm_core::json::{self, Json};
use plm_core::time::Instant;
use std::collections::VecDeque;
use std::sync::Arc;

/// Elements kept before the oldest are dropped.
pub const CAPACITY: usize = 5_000;

/// One element of the log.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Position in the log since it was cleared, for keys and pause.
    pub seq: u64,
    /// When it was seen, µs on the transport's clock (`None` if imported
    /// without a time).
    pub at: Option<Instant>,
    /// The element as plm-core decoded it.
    pub decoded: Decoded,
    /// Its fields on one line, for the table.
    pub summary: String,
}

impl Entry {
    /// `host`, `modem` or `?`.
    pub fn from(&self) -> &str {
        self.decoded.from.as_deref().unwrap_or("?")
    }

    /// The command name, the kind for other elements.
    pub fn title(&self) -> String {
        match &self.decoded.command {
            Some(Json::String(s)) => s.clone(),
            Some(_) => match self.decoded.code {
                Some(c) => format!("unknown command {c:02X}h"),
                None => "unknown command".to_string(),
            },
            None => match self.decoded.kind.as_str() {
                "ack" => "ACK".to_string(),
                "nak" => "NAK".to_string(),
                "status" => "status message".to_string(),
                other => other.to_string(),
            },
        }
    }

    /// The object of the JSON Lines export: `time_us` (when known), then
    /// what `plm decode` prints for the element.
    pub fn to_json(&self) -> Json {
        let mut o = json::Object::new();
        if let Some(t) = self.at {
            o.insert("time_us", Json::from(t));
        }
        if let Json::Object(members) = self.decoded.to_json() {
            o.extend(members);
        }
        Json::Object(o)
    }

    /// The line of the JSON Lines export.
    pub fn to_json_line(&self) -> String {
        self.to_json().to_string()
    }
}

/// A field value as people read it: strings without quotes.
fn show(v: &Json) -> String {
    match v {
        Json::String(s) => s.clone(),
        Json::Null => "–".to_string(),
        other => other.to_string(),
    }
}

/// The fields of an element on one line.
pub fn summary(d: &Decoded) -> String {
    let mut parts: Vec<String> = Vec::new();
    if let Some(fields) = &d.fields {
        for (k, v) in fields {
            parts.push(format!("{k}={}", show(v)));
        }
    }
    if d.checksum_ok == Some(false) {
        parts.push("WRONG CHECKSUM".to_string());
    }
    if let Some(r) = &d.reason {
        parts.push(format!("reason={r}"));
    }
    if let Some(e) = &d.error {
        parts.push(format!("error: {e}"));
    }
    if let Some(w) = &d.warning {
        parts.push(format!("warning: {w}"));
    }
    // UM0932 3.2.7: the modem repeats a frame (STX 03h) it got no ACK for
    // within T_ACK; a host's ACK that comes after the repeat began was late.
    if d.repeat == Some(true) {
        parts.push("repeat (STX 03h): no ACK came within T_ACK".into());
    }
    if d.after_t_ack == Some(true) {
        parts.push("ACK after T_ACK: the modem had begun its repeat".into());
    }
    parts.join("  ")
}

/// The bounded log.
#[derive(Debug, Clone, PartialEq)]
pub struct TrafficLog {
    /// Shared with the rows on screen, so that showing them copies nothing.
    entries: VecDeque<Arc<Entry>>,
    capacity: usize,
    next_seq: u64,
    dropped: u64,
}

impl Default for TrafficLog {
    fn default() -> Self {
        TrafficLog::with_capacity(CAPACITY)
    }
}

impl TrafficLog {
    /// A log that keeps at most `capacity` elements.
    pub fn with_capacity(capacity: usize) -> Self {
        TrafficLog {
            entries: VecDeque::new(),
            capacity: capacity.max(1),
            next_seq: 0,
            dropped: 0,
        }
    }

    /// Adds an element, dropping the oldest when full.
    pub fn push(&mut self, at: Option<Instant>, decoded: Decoded) {
        if self.entries.len() == self.capacity {
            self.entries.pop_front();
            self.dropped += 1;
        }
        let summary = summary(&decoded);
        self.entries.push_back(Arc::new(Entry {
            seq: self.next_seq,
            at,
            decoded,
            summary,
        }));
        self.next_seq += 1;
    }

    /// Empties the log.
    pub fn clear(&mut self) {
        self.entries.clear();
        self.dropped = 0;
    }

    /// Elements kept.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing is kept.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Elements dropped because the buffer was full.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// The sequence number the next element will get.
    pub fn next_seq(&self) -> u64 {
        self.next_seq
    }

    /// The elements, oldest first.
    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &Arc<Entry>> {
        self.entries.iter()
    }

    /// The element with this sequence number.
    pub fn get(&self, seq: u64) -> Option<&Arc<Entry>> {
        let first = self.entries.front()?.seq;
        self.entries.get(seq.checked_sub(first)? as usize)
    }

    /// The whole log as JSON Lines.
    pub fn export(&self) -> String {
        let mut s = String::new();
        for e in &self.entries {
            s.push_str(&e.to_json_line());
            s.push('\n');
        }
        s
    }

    /// Replaces the log with the elements of a JSON Lines text (an export,
    /// or `plm decode` output). Lines that are not elements are skipped and
    /// reported; nothing is imported if no line is.
    pub fn import(&mut self, text: &str) -> Result<Imported, String> {
        let mut elements = Vec::new();
        let mut skipped = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            match parse_line(line) {
                Ok(e) => elements.push(e),
                Err(why) => skipped.push(format!("line {}: {why}", i + 1)),
            }
        }
        if elements.is_empty() {
            return Err(match skipped.first() {
                Some(first) => format!("no traffic element in the file ({first})"),
                None => "the file is empty".to_string(),
            });
        }
        self.clear();
        let count = elements.len();
        for (at, d) in elements {
            self.push(at, d);
        }
        Ok(Imported { count, skipped })
    }
}

/// Whether rows shown from the log changed: (how many matched, the entries
/// shown), compared by identity (the log only appends, drops or clears),
/// not field by field. The compare of every memo of log rows.
pub fn rows_changed(
    old: Option<&(usize, Vec<Arc<Entry>>)>,
    new: Option<&(usize, Vec<Arc<Entry>>)>,
) -> bool {
    match (old, new) {
        (Some(a), Some(b)) => {
            a.0 != b.0
                || a.1.len() != b.1.len()
                || a.1.iter().zip(&b.1).any(|(x, y)| !Arc::ptr_eq(x, y))
        }
        _ => true,
    }
}

/// What an import read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Imported {
    /// Elements imported.
    pub count: usize,
    /// Lines skipped, each with its number and why.
    pub skipped: Vec<String>,
}

fn parse_line(line: &str) -> Result<(Option<Instant>, Decoded), String> {
    let v = json::parse(line).map_err(|e| format!("not JSON ({e})"))?;
    let Json::Object(mut map) = v else {
        return Err("not a JSON object".to_string());
    };
    let at = match map.remove("time_us") {
        None => None,
        Some(t) => Some(
            t.as_u64()
                .ok_or_else(|| "time_us is not a whole number of µs".to_string())?,
        ),
    };
    let d = Decoded::from_json(&Json::Object(map)).map_err(|e| format!("not an element ({e})"))?;
    plm_core::hex::parse(&d.hex).map_err(|e| format!("hex: {e}"))?;
    Ok((at, d))
}

/// Which elements to show.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Filter {
    /// `host`, `modem`, or empty for both.
    pub from: String,
    /// `frame`, `ack`, `nak`, `status`, `garbage`, or empty for all.
    pub kind: String,
    /// A command name (`MIB_ReadConfirm`), or empty for all.
    pub command: String,
}

impl Filter {
    /// Whether `e` passes.
    pub fn matches(&self, e: &Entry) -> bool {
        (self.from.is_empty() || e.from() == self.from)
            && (self.kind.is_empty() || e.decoded.kind == self.kind)
            && (self.command.is_empty()
                || e.decoded.command.as_ref().and_then(|c| c.as_str()) == Some(&self.command))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use plm_core::decode::decode_all;
    use plm_core::link::{Dialect, Source};

    fn elements(source: Source, hex: &str) -> Vec<Decoded> {
        let bytes = plm_core::hex::parse(hex).unwrap();
        decode_all(Dialect::St7580, source, &bytes)
    }

    fn log() -> TrafficLog {
        let mut log = TrafficLog::default();
        // PingRequest (host), then ACK, status and PingConfirm (modem).
        for (i, d) in elements(Source::Host, "02 02 2c 01 02 31 00")
            .into_iter()
            .chain(elements(Source::Modem, "06 3f 11 02 02 2d 01 02 32 00"))
            .enumerate()
        {
            log.push(Some(1_000 * i as u64), d);
        }
        log
    }

    #[test]
    fn the_summary_says_what_the_manual_forbids() {
        // BIO_ResetConfirm with data 01h (UM0932 3.3.2: always 00h).
        let d = &elements(Source::Modem, "02 01 3d 01 3f 00")[0];
        assert!(
            summary(d).contains("warning: BIO_ResetConfirm data is always 00h"),
            "{}",
            summary(d)
        );
    }

    #[test]
    fn the_summary_names_a_repeat_and_a_late_ack() {
        // BIO_ResetConfirm sent again with STX 03h (UM0932 3.2.7).
        let d = &elements(Source::Modem, "03 01 3d 00 3e 00")[0];
        assert!(summary(d).contains("repeat (STX 03h)"), "{}", summary(d));
        let mut ack = elements(Source::Host, "06").remove(0);
        assert!(!summary(&ack).contains("after T_ACK"));
        ack.after_t_ack = Some(true);
        assert!(
            summary(&ack).contains("ACK after T_ACK"),
            "{}",
            summary(&ack)
        );
    }

    #[test]
    fn a_full_buffer_drops_the_oldest_and_counts_them() {
        let mut log = TrafficLog::with_capacity(3);
        for d in elements(Source::Modem, "06 06 15 06 15") {
            log.push(None, d);
        }
        assert_eq!(log.len(), 3);
        assert_eq!(log.dropped(), 2);
        assert_eq!(log.iter().next().map(|e| e.seq), Some(2));
        assert_eq!(log.get(4).map(|e| e.decoded.kind.as_str()), Some("nak"));
        assert_eq!(log.get(1), None);
    }

    #[test]
    fn filters_by_direction_kind_and_command() {
        let log = log();
        let titles = |f: &Filter| -> Vec<String> {
            log.iter()
                .filter(|e| f.matches(e))
                .map(|e| e.title())
                .collect()
        };
        assert_eq!(
            titles(&Filter::default()),
            ["PingRequest", "ACK", "status message", "PingConfirm"]
        );
        let modem_frames = Filter {
            from: "modem".into(),
            kind: "frame".into(),
            ..Filter::default()
        };
        assert_eq!(titles(&modem_frames), ["PingConfirm"]);
        let cmd = Filter {
            command: "PingRequest".into(),
            ..Filter::default()
        };
        assert_eq!(titles(&cmd), ["PingRequest"]);
    }

    #[test]
    fn export_then_import_gives_the_same_log() {
        let log = log();
        let text = log.export();
        assert_eq!(text.lines().count(), 4);
        assert!(
            text.starts_with(r#"{"time_us":0,"kind":"frame","from":"host","hex":"02022c0102310"#)
        );
        let mut back = TrafficLog::default();
        let got = back.import(&text).unwrap();
        assert_eq!(got.count, 4);
        let strip =
            |l: &TrafficLog| -> Vec<_> { l.iter().map(|e| (e.at, e.decoded.clone())).collect() };
        assert_eq!(strip(&back), strip(&log));
    }

    #[test]
    fn an_unknown_command_stays_unknown_through_export_and_import() {
        let mut log = TrafficLog::default();
        for d in elements(Source::Modem, "02 00 7f 7f 00") {
            log.push(Some(5), d);
        }
        let text = log.export();
        assert!(text.contains(r#""command":null"#), "{text}");
        let mut back = TrafficLog::default();
        back.import(&text).unwrap();
        assert_eq!(back.iter().next().unwrap().title(), "unknown command 7Fh");
        assert_eq!(back.export(), text);
    }

    #[test]
    fn import_takes_plm_decode_output_and_reports_bad_lines() {
        let plain: Vec<String> = elements(Source::Any, "02 00 2c 2c 00 06")
            .iter()
            .map(|d| d.to_json().to_string())
            .collect();
        let text = format!("{}\nnot json\n\n{}\n[1]\n", plain[0], plain[1]);
        let mut log = TrafficLog::default();
        let got = log.import(&text).unwrap();
        assert_eq!(got.count, 2);
        assert_eq!(got.skipped.len(), 2);
        assert!(
            got.skipped[0].starts_with("line 2: not JSON"),
            "{:?}",
            got.skipped
        );
        assert_eq!(log.iter().next().unwrap().title(), "PingRequest");
        assert!(log.import("nothing here").is_err());
        assert_eq!(log.len(), 2, "a failed import keeps the log");
    }

    /// A damaged or hostile file, read as the Traffic import reads it
    /// (plm_core::file::text, then the import): refused in words, the
    /// log as it was.
    #[test]
    fn a_damaged_log_file_is_refused_and_the_log_kept() {
        let mut log = log();
        let before = log.export();
        let line = before.lines().next().unwrap().as_bytes().to_vec();
        let mut files: Vec<Vec<u8>> = (0..line.len()).map(|n| line[..n].to_vec()).collect();
        files.extend([
            [
                &[0xFF, 0xFE][..],
                &line.iter().flat_map(|&b| [b, 0]).collect::<Vec<_>>(),
            ]
            .concat(),
            [&line[..], b"\xC3("].concat(),
            [&line[..5], b"\0", &line[5..]].concat(),
            vec![b'['; plm_core::file::FILE_MAX + 1],
            "9".repeat(1 << 20).into_bytes(),
            "{\"a\":".repeat(1 << 18).into_bytes(),
        ]);
        for bytes in files {
            let why = plm_core::file::text(&bytes)
                .and_then(|text| log.import(text))
                .unwrap_err();
            assert!(why.len() > 15, "{why}");
            assert_eq!(log.export(), before, "{why}");
        }
    }
}
