//! What the MoorDyn cross-code tests share: running one of `verify/moordyn/`'s scripts on a case.

use serde_json::Value;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `verify/moordyn/<script>` on `case` (JSON on its stdin) in the tests' own Python, with
/// MoorDyn installed under target/ the first time, and returns its answer (JSON on its stdout).
pub fn moordyn(script: &str, case: &Value) -> Value {
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("moordyn")
        .join(script);
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    let python = cdpr_testing::python::interpreter(target);
    let mut child = Command::new(&python)
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{}: {e}", python.display()));
    child
        .stdin
        .take()
        .unwrap()
        .write_all(case.to_string().as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "MoorDyn case failed ({}): {}",
        out.status,
        stderr.lines().rev().take(15).collect::<Vec<_>>().join("\n")
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "MoorDyn's answer is not JSON ({e}); is moordyn installed for {}? {stderr}",
            python.display()
        )
    })
}
