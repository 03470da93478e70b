//! Text from the model file (its file name, docs, written values) on its
//! way into generated code, where it lands in comments and doc attributes:
//! one function makes it inert there.

/// `text` with every character that could end a comment line or change
/// how the code around it reads written as a visible escape `\u{…}`:
/// line breaks (LF, CR, and the other Unicode line and paragraph
/// separators), other control characters, and the bidirectional
/// formatting characters (rustc denies them in comments and literals, as
/// they can make code display other than it compiles). Tabs stay.
pub(crate) fn inert(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if unsafe_in_comment(c) {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    out
}

/// Whether `c` may not appear as itself in a generated comment.
fn unsafe_in_comment(c: char) -> bool {
    (c.is_control() && c != '\t')
        || matches!(
            c,
            // Line and paragraph separators, next line.
            '\u{2028}' | '\u{2029}' | '\u{85}'
            // Bidirectional marks, embeddings, overrides and isolates.
            | '\u{61c}' | '\u{200e}' | '\u{200f}'
            | '\u{202a}'..='\u{202e}'
            | '\u{2066}'..='\u{2069}'
        )
}

#[cfg(test)]
mod tests {
    use super::inert;

    #[test]
    fn line_breaks_controls_and_bidi_become_escapes() {
        assert_eq!(
            inert("plain text, */ and /* stay"),
            "plain text, */ and /* stay"
        );
        assert_eq!(inert("a\nb"), "a\\u{a}b");
        assert_eq!(inert("a\r\nb\rc"), "a\\u{d}\\u{a}b\\u{d}c");
        assert_eq!(
            inert("x\u{202e}y\u{2066}z\u{2069}"),
            "x\\u{202e}y\\u{2066}z\\u{2069}"
        );
        assert_eq!(
            inert("bell\u{7} nul\u{0} del\u{7f}"),
            "bell\\u{7} nul\\u{0} del\\u{7f}"
        );
        assert_eq!(
            inert("sep\u{2028}\u{2029}\u{85}"),
            "sep\\u{2028}\\u{2029}\\u{85}"
        );
        assert_eq!(inert("tab\tand ünïcödé π"), "tab\tand ünïcödé π");
        // Nothing unsafe is left in any character's output.
        for c in (0..0x3000u32).filter_map(char::from_u32) {
            let s = inert(&c.to_string());
            assert!(s.chars().all(|d| !super::unsafe_in_comment(d)), "{c:?}");
        }
    }
}
