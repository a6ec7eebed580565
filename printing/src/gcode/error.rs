//! Why a G-code file is refused: every error names the line (1-based), its text and the rule it
//! broke, so a user can find it in the slicer's output.

use thiserror::Error;

/// A G-code line the reader refuses.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GcodeError {
    /// Not G-code: a word without a number, a number that does not parse, a stray character.
    #[error("G-code line {line}: `{text}`: {reason}")]
    Malformed {
        /// 1-based line number.
        line: usize,
        /// The line as written.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A command the reader understands but does not carry out (arcs, inches).
    #[error("G-code line {line}: `{text}`: {command} is not supported: {hint}")]
    Unsupported {
        /// 1-based line number.
        line: usize,
        /// The line as written.
        text: String,
        /// The command word, e.g. `G2`.
        command: String,
        /// What to do instead.
        hint: String,
    },
    /// A parameter outside its allowed range (a feed rate ≤ 0, a negative dwell, …).
    #[error("G-code line {line}: `{text}`: {key} = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// 1-based line number.
        line: usize,
        /// The line as written.
        text: String,
        /// The parameter, e.g. `F`.
        key: String,
        /// Its value as written.
        value: f64,
        /// The allowed range.
        allowed: String,
    },
}
