//! README's `motorgen` examples are tests (issue 31): every ```` ```console ```` block of
//! README.md runs with trycmd against the built `motorgen`, its shown output (stdout and
//! stderr as a terminal shows them) and exit code checked; `...` and `[..]` elide what
//! varies or what other parts of the design summary may change.
//!
//! The commands run in a scratch folder holding copies of `motors/` and `boards/`, as a
//! user's working directory would (the `generate`, `new` and `report` examples write
//! there, never into the repository). This binary holds this one test because it sets the
//! process's working directory.
//!
//! After an intended change of an example's output, edit README.md to match (trycmd's
//! overwrite mode does not apply to Markdown).

use std::path::Path;

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap_or_else(|e| panic!("cannot create {}: {e}", to.display()));
    for entry in std::fs::read_dir(from).unwrap_or_else(|e| panic!("cannot read {}: {e}", from.display())) {
        let path = entry.expect("a directory entry").path();
        if path.is_file() {
            let target = to.join(path.file_name().expect("a file name"));
            std::fs::copy(&path, &target).unwrap_or_else(|e| panic!("cannot copy {}: {e}", path.display()));
        }
    }
}

#[test]
fn readme_examples() {
    let repo = motor_test_support::repo();
    let readme = repo.join("README.md");
    let text = std::fs::read_to_string(&readme).expect("README.md is readable");
    // A README whose examples lost their `console` fence would pass with nothing run.
    let blocks = text.matches("```console\n$ motorgen ").count();
    assert!(blocks >= 1, "README.md has no ```console block of motorgen commands");

    let scratch = motor_test_support::tmp("readme", "examples");
    copy_dir(&repo.join("motors"), &scratch.join("motors"));
    copy_dir(&repo.join("boards"), &scratch.join("boards"));
    std::env::set_current_dir(&scratch).expect("the scratch folder is a working directory");

    trycmd::TestCases::new()
        .register_bin("motorgen", Path::new(env!("CARGO_BIN_EXE_motorgen")))
        .case(&readme);
}
