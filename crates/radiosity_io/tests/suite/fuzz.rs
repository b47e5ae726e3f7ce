//! Mutated scene files never panic the loader: every mutation of the Cornell box file gives
//! `Ok` or a one-line `Err`. The mutations are deterministic (a fixed xorshift seed), so a
//! failure names a mutation that can be replayed.

use std::panic::{AssertUnwindSafe, catch_unwind};

use radiosity_io::parse_scene;

const CORNELL: &str = include_str!("../../../../scenes/cornell.toml");

use radiosity_core::random::XorShift64;

/// Fragments inserted or written over the text: TOML punctuation, the special floats, a
/// multi-byte character, escapes, headers and keys that shift the structure.
const FRAGMENTS: &[&str] = &[
    "[",
    "]",
    "{",
    "}",
    "=",
    "\"",
    "'",
    ",",
    ".",
    "-",
    "+",
    "#",
    "\n",
    " ",
    "\\",
    "\\n",
    "0",
    "1",
    "9",
    "e",
    "nan",
    "inf",
    "-inf",
    "1e999",
    "-0",
    "1e-320",
    "é",
    "ρ",
    "\u{0}",
    "[[object]]\n",
    "[[material]]\n",
    "[camera]\n",
    "[mesh]\n",
    "name = \"x\"\n",
    "type = \"box\"\n",
    "type = \"sphere\"\n",
    "type = \"mesh\"\n",
    "normals = \"inward\"\n",
    "radius = 0\n",
    "emission = [1, 1, 1]\n",
    "max_shots = -1\n",
    "\"\"\"",
];

/// Applies one random edit to `chars` (a char vector keeps the text valid UTF-8).
fn mutate(chars: &mut Vec<char>, rng: &mut XorShift64) {
    let len = chars.len().max(1);
    match rng.below(6) {
        0 => chars.truncate(rng.below(len)),
        1 => {
            // Delete a short run.
            let at = rng.below(len).min(chars.len());
            let end = (at + 1 + rng.below(4)).min(chars.len());
            chars.drain(at..end);
        }
        2 => {
            let at = rng.below(len + 1).min(chars.len());
            let fragment = FRAGMENTS[rng.below(FRAGMENTS.len())];
            chars.splice(at..at, fragment.chars());
        }
        3 => {
            // Overwrite one character.
            if !chars.is_empty() {
                let at = rng.below(chars.len());
                chars[at] = FRAGMENTS[rng.below(FRAGMENTS.len())].chars().next().unwrap_or('x');
            }
        }
        4 => {
            // Flip a bit of an ASCII character (staying ASCII).
            if !chars.is_empty() {
                let at = rng.below(chars.len());
                if chars[at].is_ascii() {
                    chars[at] = char::from((chars[at] as u8) ^ (1 << rng.below(7)));
                }
            }
        }
        _ => {
            // Duplicate a line somewhere else (repeated keys, tables, entries).
            let text: String = chars.iter().collect();
            let lines: Vec<&str> = text.split_inclusive('\n').collect();
            if !lines.is_empty() {
                let line = lines[rng.below(lines.len())].to_owned();
                let at = rng.below(lines.len());
                let mut out: String = lines[..at].concat();
                out.push_str(&line);
                out.push_str(&lines[at..].concat());
                *chars = out.chars().collect();
            }
        }
    }
}

/// Parses `text`, turning a panic into a test failure that names `what`.
fn parse_without_panic(text: &str, what: &str) {
    match catch_unwind(AssertUnwindSafe(|| parse_scene(text, "mutated.toml"))) {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => {
            let s = e.to_string();
            assert_eq!(s.lines().count(), 1, "{what}: error is not one line: {s}");
            assert!(s.starts_with("mutated.toml:"), "{what}: {s}");
        }
        Err(_) => panic!("{what} panicked the loader; text:\n{text}"),
    }
}

#[test]
fn random_mutations_never_panic() {
    let base: Vec<char> = CORNELL.chars().collect();
    let mut rng = XorShift64::new(0x9e37_79b9_7f4a_7c15);
    let mut accepted = 0;
    for i in 0..2000 {
        let mut chars = base.clone();
        // One to three edits, so some mutants are broken in more than one place.
        for _ in 0..1 + rng.below(3) {
            mutate(&mut chars, &mut rng);
        }
        let text: String = chars.into_iter().collect();
        parse_without_panic(&text, &format!("mutation {i}"));
        accepted += usize::from(parse_scene(&text, "m.toml").is_ok());
    }
    // Most single edits of a valid file (in a comment, a digit) leave it valid; if none
    // did, the mutations would not be exercising the validation stage.
    assert!(accepted > 50, "only {accepted} mutants loaded");
}

#[test]
fn every_truncation_never_panics() {
    // Every 3rd cut point (all of them would only repeat the same states).
    for (i, (at, _)) in CORNELL.char_indices().enumerate().filter(|(i, _)| i % 3 == 0) {
        parse_without_panic(&CORNELL[..at], &format!("truncation {i} at byte {at}"));
    }
}
