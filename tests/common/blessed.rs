//! Committed generated files (model sources written by a test so that the macro compiles
//! them): a test fails when the committed file differs from what the generator writes now,
//! and `MBS_BLESS=1` rewrites it.

/// Fails unless the file at `path` (relative to the package) holds `text`; with `MBS_BLESS`
/// set, writes `text` there instead. `test` names the test target that regenerates it.
pub fn assert_current(path: &str, text: &str, test: &str) {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    let committed = std::fs::read_to_string(&full).unwrap_or_default();
    if committed == text {
        return;
    }
    if std::env::var_os("MBS_BLESS").is_some() {
        std::fs::write(&full, text).expect("writing the generated file");
    } else {
        panic!(
            "{path} is stale: regenerate it with `MBS_BLESS=1 cargo test --release --test {test}`"
        );
    }
}
