//! The documentation's figures against what a test computes: a test that computes a figure the
//! README (or a page of `docs/`) quotes checks that the text still quotes it, so that a change
//! of the code that moves the figure fails until the text says what the code does now. The
//! text's line breaks do not matter: runs of white space compare as one space.
#![allow(dead_code)]

/// The file `path` (relative to the repository's root).
fn read(path: &str) -> String {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("reading {path}: {e}"))
}

/// The file `path`, its white space collapsed.
fn text(path: &str) -> String {
    collapse(&read(path))
}

/// `s` with each run of white space replaced by one space.
fn collapse(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Fails unless `path` contains every phrase of `phrases` (white space collapsed), naming the
/// ones it lacks: each is a figure this test computed, written as the text writes it.
#[track_caller]
pub fn says(path: &str, phrases: &[String]) {
    let doc = text(path);
    let missing: Vec<&String> = phrases
        .iter()
        .filter(|p| !doc.contains(&collapse(p)))
        .collect();
    assert!(
        missing.is_empty(),
        "{path} no longer quotes what this test computed; write these figures into it \
         (or correct the test's phrase):\n{}",
        missing
            .iter()
            .map(|p| format!("  `{p}`"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// The row of a table in `path` whose first cell is `first` (white space collapsed), or a
/// failure naming the row it lacks.
#[track_caller]
pub fn row(path: &str, first: &str) -> String {
    let start = format!("| {first} |");
    read(path)
        .lines()
        .map(collapse)
        .find(|l| l.starts_with(&start))
        .unwrap_or_else(|| panic!("{path} has no table row `{start} …`"))
}

/// A count under ten in words, as the documents write it ("no" for zero); larger ones in
/// digits.
pub fn word(n: usize) -> String {
    const WORDS: [&str; 10] = [
        "no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine",
    ];
    WORDS
        .get(n)
        .map_or_else(|| n.to_string(), |w| w.to_string())
}

/// `s` with its hyphen-minus signs written as the documents write them: −5.
pub fn minus(s: String) -> String {
    s.replace('-', "−")
}

/// `n` with commas between thousands, as the documentation writes counts: 12,524.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}
