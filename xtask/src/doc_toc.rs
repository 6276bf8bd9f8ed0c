//! The table of contents of `docs/protocol-notes.md`, checked by a unit
//! test (run by `cargo xtask test` with every other test) so that it
//! cannot drift from the headings: a `##` or `###` heading added,
//! renamed or removed without its line in the contents fails the test,
//! which prints the contents to paste.

use std::collections::HashMap;

/// The `##` heading of the contents block; it does not list itself.
const CONTENTS: &str = "Contents";

/// GitHub's anchor of a heading's text: lowercase, everything but
/// letters, digits, `_`, `-` and spaces dropped, spaces made `-`.
fn slug(text: &str) -> String {
    text.to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The headings of `markdown` outside fenced code: (level, text, anchor),
/// a repeated anchor numbered `-1`, `-2`… as GitHub does.
fn headings(markdown: &str) -> Vec<(usize, &str, String)> {
    let mut fenced = false;
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    for line in markdown.lines() {
        if line.starts_with("```") || line.starts_with("~~~") {
            fenced = !fenced;
        }
        let level = line.bytes().take_while(|&b| b == b'#').count();
        if fenced || level == 0 || !line[level..].starts_with(' ') {
            continue;
        }
        let text = line[level..].trim();
        let base = slug(text);
        let n = seen.entry(base.clone()).or_insert(0);
        let anchor = match *n {
            0 => base,
            k => format!("{base}-{k}"),
        };
        *n += 1;
        out.push((level, text, anchor));
    }
    out
}

/// The contents `markdown` should have: one line per `##` and `###`
/// heading but the contents' own, `###` indented under its `##`.
fn expected(markdown: &str) -> Vec<String> {
    headings(markdown)
        .into_iter()
        .filter(|(level, text, _)| (2..=3).contains(level) && *text != CONTENTS)
        .map(|(level, text, anchor)| {
            let indent = if level == 3 { "  " } else { "" };
            format!("{indent}- [{text}](#{anchor})")
        })
        .collect()
}

/// The list lines of the contents block as written: from its heading to
/// the next heading, blank lines left out.
fn written(markdown: &str) -> Option<Vec<String>> {
    let heading = format!("## {CONTENTS}");
    let start = markdown.lines().position(|l| l == heading)?;
    Some(
        markdown
            .lines()
            .skip(start + 1)
            .take_while(|l| !l.starts_with('#'))
            .filter(|l| !l.trim().is_empty())
            .map(str::to_string)
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anchors_are_githubs() {
        assert_eq!(
            slug("UM0932 (ST7580) — quirks of the seed"),
            "um0932-st7580--quirks-of-the-seed"
        );
        assert_eq!(
            slug("Host link engine (`link::host`)"),
            "host-link-engine-linkhost"
        );
        assert_eq!(
            slug("The board's flash (`plm_sim::flash`)"),
            "the-boards-flash-plm_simflash"
        );
        let doc = "# T\n## A\n```\n## not a heading\n```\n### B\n## A\n####x\n";
        let anchors: Vec<_> = headings(doc).into_iter().map(|h| h.2).collect();
        assert_eq!(anchors, ["t", "a", "b", "a-1"]);
    }

    #[test]
    fn a_heading_missing_from_the_contents_is_found() {
        let doc = "# T\n\n## Contents\n\n- [A](#a)\n\n## A\n### B\n";
        assert_eq!(expected(doc), ["- [A](#a)", "  - [B](#b)"]);
        assert_ne!(written(doc), Some(expected(doc)));
        assert_eq!(written("# T\n## A\n"), None);
    }

    #[test]
    fn protocol_notes_contents_list_every_section() {
        let path = crate::util::root().join("docs/protocol-notes.md");
        let doc = std::fs::read_to_string(&path).expect("docs/protocol-notes.md is readable");
        let want = expected(&doc);
        assert!(
            written(&doc).as_ref() == Some(&want),
            "the contents of docs/protocol-notes.md do not match its `##` and `###` \
             headings; put this under its `## {CONTENTS}` heading:\n\n{}\n",
            want.join("\n")
        );
    }
}
