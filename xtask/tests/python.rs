//! The Python package (`python/`, the `cdpr_bench` module) built and tested from `cargo test`:
//! maturin builds it into the tests' own virtual environment (`cdpr_testing::python`, under
//! target/), and its pytest suite runs against the CLI binary this build made: metrics and
//! samples equal to `simulate`'s bit for bit, records equal to `sweep`'s, from threads and from
//! Dask worker processes.

use std::path::Path;

#[test]
fn the_python_package_passes_its_suite_against_this_cli() {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    let python = cdpr_testing::python::interpreter(target);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    // The build goes to its own target directory: this test must not wait on the lock of the
    // build that is running it, and a release build with the extension's features shares
    // nothing with the test build anyway.
    cdpr_testing::python::run(
        cdpr_testing::python::command(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "--no-build-isolation",
                "--force-reinstall",
                "--no-deps",
            ])
            .arg(root.join("python"))
            .env("CARGO_TARGET_DIR", target.join("python-build"))
            // Optimised without fat LTO (Cargo.toml's python-test profile): a cold build in
            // 2 min 48 s instead of 3 min 54 s on 2 cores, the same numbers.
            .env("MATURIN_PEP517_ARGS", "--profile python-test"),
        "building the Python package with maturin",
    );
    cdpr_testing::python::run(
        cdpr_testing::python::command(&python)
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            .arg(root.join("python").join("tests"))
            .env("XTASK", env!("CARGO_BIN_EXE_xtask"))
            .current_dir(root),
        "the Python package's pytest suite",
    );
}
