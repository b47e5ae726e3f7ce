//! Errors as the user reads them: one line, whatever the error and whatever a file held.
//!
//! Every place that shows an error (the command line's `error: …`, the viewer's status line,
//! the scene loader's messages) goes through these two functions, so a message reads the same
//! wherever it appears and a script can take one line per error.

/// An error and its causes on one line, joined by ": " (outermost first), with control
/// characters escaped.
///
/// ```
/// let e = std::io::Error::other("disk full");
/// assert_eq!(radiosity_core::one_line(&e), "disk full");
/// ```
pub fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut parts = vec![escape_controls(&e.to_string())];
    let mut source = e.source();
    while let Some(s) = source {
        parts.push(escape_controls(&s.to_string()));
        source = s.source();
    }
    parts.join(": ")
}

/// `s` with control characters (a newline in a material name, say) escaped as Rust escapes
/// them (`\n`, `\t`, `\u{1b}`), so that a message stays one line whatever a file holds, and
/// cut to [`MAX_PART_CHARS`].
pub fn escape_controls(s: &str) -> String {
    let count = s.chars().count();
    let s: String = if count > MAX_PART_CHARS {
        let head: String = s.chars().take(MAX_PART_CHARS - 60).collect();
        format!("{head}… ({count} characters)")
    } else {
        s.to_owned()
    };
    if !s.chars().any(char::is_control) {
        return s;
    }
    s.chars().map(|c| if c.is_control() { c.escape_default().to_string() } else { c.to_string() }).collect()
}

/// Longest part of an error message kept whole, in characters; a longer one (a 1 MB key
/// echoed by the TOML parser) is cut, saying how long it was.
pub const MAX_PART_CHARS: usize = 1000;
