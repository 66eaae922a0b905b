//! Compile-fail tests: every macro error is a `compile_error!` spanned at the
//! offending argument. Accept an intended message change with
//! `TRYBUILD=overwrite cargo test -p motor-macro-diagnostics --test ui` and review the `.stderr` diff.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/*.rs");
}
