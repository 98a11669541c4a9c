//! Compile-fail UI tests: every mistake in a `multibody!` block is a compile error on the
//! offending tokens that names the construct and the fix, and nothing else fails in cascade.
//! Regenerate the expected output with `TRYBUILD=overwrite cargo test -p mbs-compile-fail`.

#[test]
fn ui() {
    trybuild::TestCases::new().compile_fail("tests/ui/*/*.rs");
}
