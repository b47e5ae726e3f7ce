//! Turning byte offsets in a scene file into what a person reads: line, column and key path.
//!
//! toml's errors carry a byte span but not the key path with array indices (its key list
//! says `object.vertices`, never *which* object), so the path is recovered from the text with
//! a small scanner that knows table headers, `[[array]]` entries, strings and comments.

use std::ops::Range;

use crate::LoadError;

/// Builds located errors for one text.
pub(crate) struct Locator<'a> {
    /// File name (or other origin) shown first in every message.
    pub(crate) origin: &'a str,
    /// The whole text, to turn spans into line and column.
    pub(crate) text: &'a str,
}

impl Locator<'_> {
    /// A [`LoadError::At`] for the value at `span`.
    pub(crate) fn at(
        &self,
        span: Range<usize>,
        key: impl Into<String>,
        message: impl Into<String>,
    ) -> LoadError {
        let (line, column) = line_col(self.text, span.start);
        LoadError::At {
            origin: one_line(self.origin),
            line,
            column,
            key: one_line(&key.into()),
            message: one_line(&message.into()),
        }
    }

    /// A [`LoadError::At`] for a toml error: its span, the key path found from the text,
    /// and toml's own message (which lists expected keys and types).
    pub(crate) fn toml_error(&self, e: &toml::de::Error) -> LoadError {
        let span = e.span().unwrap_or(0..0);
        // toml's message may run over several lines; keep all of it, on one.
        let message: Vec<&str> = e.message().lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        let message = if message.is_empty() { "invalid TOML".to_owned() } else { message.join("; ") };
        self.at(span.clone(), key_path_at(self.text, span.start), message)
    }
}

/// Longest part of an error message kept whole, in characters; a longer one (a 1 MB key
/// echoed by the TOML parser) is cut, saying how long it was.
const MAX_PART_CHARS: usize = 1000;

/// `s` with control characters (a newline in a material name, say) escaped, so that an error
/// stays one line whatever the file holds, and cut to [`MAX_PART_CHARS`].
pub(crate) fn one_line(s: &str) -> String {
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

/// 1-based (line, column) of byte `offset` in `text`; the column counts characters.
pub(crate) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text.as_bytes()[..offset.min(text.len())];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let start = before.iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);
    // Lossy because an offset could (in principle) fall inside a multi-byte character.
    let column = String::from_utf8_lossy(&before[start..]).chars().count() + 1;
    (line, column)
}

/// What one line of TOML starts with, seen at bracket depth 0.
enum LineKind {
    /// `[[name]]`: a new entry of an array of tables.
    ArrayHeader(String),
    /// `[name]`: a table.
    TableHeader(String),
    /// `key = …`, with the byte index of the text after `=`.
    Assignment(String, usize),
    /// Blank, comment, or something that does not parse.
    Other,
}

fn classify(line: &str) -> LineKind {
    let t = line.trim_start();
    let indent = line.len() - t.len();
    let header_name = |s: &str, close: &str| s.split(close).next().unwrap_or("").trim().to_owned();
    if let Some(rest) = t.strip_prefix("[[") {
        return LineKind::ArrayHeader(header_name(rest, "]]"));
    }
    if let Some(rest) = t.strip_prefix('[') {
        return LineKind::TableHeader(header_name(rest, "]"));
    }
    if let Some(eq) = t.find('=') {
        let key = t[..eq].trim();
        let bare = |c: char| c.is_alphanumeric() || "_-.\"' ".contains(c);
        if !key.is_empty() && key.chars().all(bare) {
            return LineKind::Assignment(key.to_owned(), indent + eq + 1);
        }
    }
    LineKind::Other
}

/// Change in bracket depth (`[` `{` open, `]` `}` close) over `s`, skipping strings and
/// comments. Multi-line strings are not tracked; the path is best effort.
fn depth_change(s: &str) -> i64 {
    let mut depth = 0;
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for c in s.chars() {
        match quote {
            Some(q) => {
                if escaped {
                    escaped = false;
                } else if c == '\\' && q == '"' {
                    escaped = true;
                } else if c == q {
                    quote = None;
                }
            }
            None => match c {
                '"' | '\'' => quote = Some(c),
                '#' => break,
                '[' | '{' => depth += 1,
                ']' | '}' => depth -= 1,
                _ => {}
            },
        }
    }
    depth
}

/// Best-effort key path of the value at byte `offset`, e.g. `material[1].reflectance`,
/// `object[3].faces`, `camera`; `toml` when nothing better is known.
pub(crate) fn key_path_at(text: &str, offset: usize) -> String {
    let bytes = text.as_bytes();
    let offset = offset.min(bytes.len());
    let target_start = bytes[..offset].iter().rposition(|&b| b == b'\n').map_or(0, |p| p + 1);

    let mut table = String::new();
    let mut counts: Vec<(String, usize)> = Vec::new();
    // The key whose value is still open (a multi-line array), and the bracket depth.
    let mut open_key: Option<String> = None;
    let mut depth: i64 = 0;
    let join =
        |table: &str, key: &str| if table.is_empty() { key.to_owned() } else { format!("{table}.{key}") };

    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let is_target = line_start == target_start;
        if depth > 0 {
            if is_target {
                return open_key.map_or_else(|| join(&table, "?"), |k| join(&table, &k));
            }
            depth = (depth + depth_change(line)).max(0);
        } else {
            match classify(line) {
                LineKind::ArrayHeader(name) => {
                    let n = match counts.iter_mut().find(|(k, _)| *k == name) {
                        Some((_, n)) => {
                            *n += 1;
                            *n - 1
                        }
                        None => {
                            counts.push((name.clone(), 1));
                            0
                        }
                    };
                    table = format!("{name}[{n}]");
                    if is_target {
                        return table;
                    }
                }
                LineKind::TableHeader(name) => {
                    table = name;
                    if is_target {
                        return table;
                    }
                }
                LineKind::Assignment(key, value_at) => {
                    if is_target {
                        return join(&table, &key);
                    }
                    depth = depth_change(&line[value_at..]).max(0);
                    open_key = Some(key);
                }
                LineKind::Other => {
                    if is_target {
                        return if table.is_empty() { "toml".to_owned() } else { table };
                    }
                }
            }
        }
        line_start += line.len();
        if line_start > target_start {
            break;
        }
    }
    // The offset is at the very end (after a final newline, or an empty text).
    if table.is_empty() { "toml".to_owned() } else { table }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "name = \"x\"\n[camera]\nfov_y_deg = 3\n[[material]]\nname = \"a\"\n\
                        [[material]]\nreflectance = [1, # ]\n  2, 3]\n[[object]]\nfaces = [\n  [[0, 0, 0]],\n]\n";

    fn path_of_line(line: usize) -> String {
        let offset: usize = TEXT.split_inclusive('\n').take(line - 1).map(str::len).sum();
        key_path_at(TEXT, offset + 2)
    }

    #[test]
    fn key_paths_follow_headers_and_open_arrays() {
        assert_eq!(path_of_line(1), "name");
        assert_eq!(path_of_line(2), "camera");
        assert_eq!(path_of_line(3), "camera.fov_y_deg");
        assert_eq!(path_of_line(5), "material[0].name");
        assert_eq!(path_of_line(6), "material[1]");
        // The `]` in the comment does not close the array: line 8 still belongs to it.
        assert_eq!(path_of_line(8), "material[1].reflectance");
        assert_eq!(path_of_line(9), "object[0]");
        // A continuation line starting with `[[` is not an array-of-tables header.
        assert_eq!(path_of_line(11), "object[0].faces");
        assert_eq!(key_path_at(TEXT, TEXT.len()), "object[0]");
        assert_eq!(key_path_at("", 0), "toml");
    }

    #[test]
    fn line_and_column_count_characters() {
        assert_eq!(line_col("ab\ncd", 0), (1, 1));
        assert_eq!(line_col("ab\ncd", 4), (2, 2));
        assert_eq!(line_col("ρρ\nx", 4), (1, 3));
        assert_eq!(line_col("ab", 99), (1, 3));
    }

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(one_line("a\nb\tc"), "a\\nb\\tc");
        assert_eq!(one_line("plain"), "plain");
    }
}
