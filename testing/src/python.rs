//! The Python the tests need, installed by the tests themselves: a virtual environment under
//! the build's target directory with the packages of `testing/python-requirements.txt` (MoorDyn
//! for the cross-code tests, pytest, Dask and maturin for the Python package's suite), made
//! once under a file lock (test binaries run at once) and rebuilt when the requirements change.
//! `cargo test --workspace` on a fresh machine then needs nothing installed by hand; only
//! PyPI must be reachable the first time.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The requirements, compiled in: the environment is rebuilt when they change.
const REQUIREMENTS: &str = include_str!("../python-requirements.txt");

/// The environment variable that names another interpreter to use instead (one that has the
/// requirements already).
pub const OVERRIDE: &str = "CDPR_PYTHON";

/// The interpreter of the tests' environment under `target` (the build's target directory,
/// e.g. the parent of `env!("CARGO_TARGET_TMPDIR")`), made first if it is missing or its
/// requirements changed. Panics, naming the step and its output, when it cannot be made: a
/// test that needs it cannot run without it.
pub fn interpreter(target: &Path) -> PathBuf {
    if let Ok(python) = std::env::var(OVERRIDE) {
        return PathBuf::from(python);
    }
    let home = target.join("test-python");
    std::fs::create_dir_all(&home).unwrap_or_else(|e| panic!("{}: {e}", home.display()));
    let lock_path = home.join(".lock");
    let lock = OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .unwrap_or_else(|e| panic!("{}: {e}", lock_path.display()));
    lock.lock()
        .unwrap_or_else(|e| panic!("locking {}: {e}", lock_path.display()));
    let venv = home.join("venv");
    let python = venv.join("bin").join("python");
    let stamp = home.join("requirements.installed");
    let current = std::fs::read_to_string(&stamp).ok();
    if !python.exists() || current.as_deref() != Some(REQUIREMENTS) {
        let _ = std::fs::remove_dir_all(&venv);
        let system = std::env::var("PYTHON3").unwrap_or_else(|_| "python3".into());
        run(
            Command::new(&system).args(["-m", "venv"]).arg(&venv),
            "creating the venv",
        );
        let requirements = home.join("requirements.txt");
        std::fs::write(&requirements, REQUIREMENTS).expect("writing the requirements");
        run(
            Command::new(&python)
                .args([
                    "-m",
                    "pip",
                    "install",
                    "--quiet",
                    "--disable-pip-version-check",
                    "-r",
                ])
                .arg(&requirements),
            "installing the tests' Python packages from PyPI",
        );
        let mut f = std::fs::File::create(&stamp).expect("writing the stamp");
        f.write_all(REQUIREMENTS.as_bytes())
            .expect("writing the stamp");
    }
    drop(lock);
    python
}

/// A command running `python` with its environment's `bin` first on PATH (where pip puts the
/// tools it installs, e.g. maturin, which the package's build calls by name).
pub fn command(python: &Path) -> Command {
    let mut c = Command::new(python);
    if let Some(bin) = python.parent() {
        let path = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![bin.to_path_buf()];
        paths.extend(std::env::split_paths(&path));
        if let Ok(joined) = std::env::join_paths(paths) {
            c.env("PATH", joined);
        }
    }
    c
}

/// Runs `command`, panicking with its output when it fails.
pub fn run(command: &mut Command, what: &str) {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {command:?}: {e}"));
    assert!(
        output.status.success(),
        "{what} failed ({command:?}):\n{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}
