//! One G-code line split into its command and parameter words (upper-cased, as firmware reads
//! them): `G1 X10.5 Y-3 E.02 F1800 ; comment` → `G1`, [(X, 10.5), (Y, −3), (E, 0.02), (F, 1800)].
//! A leading line number `N…` and a trailing checksum `*…` are dropped; the comment is kept for
//! the slicer's annotations (`;TYPE:`, `;LAYER_CHANGE`).

use super::GcodeError;

/// A line's words. Parameters are parsed only for the commands the reader carries out
/// ([`Line::parameters`]): other commands (`M117 text`, `SET_FAN_SPEED FAN=…`) have free-form
/// arguments.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Line<'a> {
    /// The command word, upper-cased (`G1`, `M204`, `M862.3`, `SET_VELOCITY_LIMIT`); empty for a
    /// line holding only a comment or nothing.
    pub command: String,
    /// Everything after the command word and before the comment or checksum.
    pub arguments: &'a str,
    /// The comment after `;`, without it (trimmed), if any.
    pub comment: Option<&'a str>,
}

impl<'a> Line<'a> {
    /// Splits `text` (one line without its newline).
    pub fn split(text: &'a str) -> Line<'a> {
        let (code, comment) = match text.find(';') {
            Some(at) => (&text[..at], Some(text[at + 1..].trim())),
            None => (text, None),
        };
        let code = match code.find('*') {
            Some(at) => &code[..at],
            None => code,
        };
        let mut code = code.trim_start();
        // A line number `N123` before the command.
        if code.starts_with(['N', 'n']) && code[1..].starts_with(|c: char| c.is_ascii_digit()) {
            let end = code[1..]
                .find(|c: char| !c.is_ascii_digit())
                .map_or(code.len(), |i| i + 1);
            code = code[end..].trim_start();
        }
        let end = command_end(code);
        Line {
            command: code[..end].to_ascii_uppercase(),
            arguments: code[end..].trim(),
            comment,
        }
    }

    /// The parameter words `letter value` of a traditional command, in order; a letter without
    /// a value (G28's `X`) gives `None`. Refused: anything but letters and numbers, a number that
    /// does not parse, a letter given twice.
    pub fn parameters(
        &self,
        line: usize,
        text: &str,
    ) -> Result<Vec<(char, Option<f64>)>, GcodeError> {
        let malformed = |reason: String| GcodeError::Malformed {
            line,
            text: text.to_string(),
            reason,
        };
        let mut words: Vec<(char, Option<f64>)> = Vec::new();
        let mut rest = self.arguments.trim_start();
        while let Some(letter) = rest.chars().next() {
            if !letter.is_ascii_alphabetic() {
                return Err(malformed(format!(
                    "`{letter}` where a parameter letter (A–Z) was expected"
                )));
            }
            let letter = letter.to_ascii_uppercase();
            let number = &rest[1..];
            let end = number
                .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '+' | '-')))
                .unwrap_or(number.len());
            let value = match number[..end].trim() {
                "" => None,
                digits => Some(digits.parse::<f64>().map_err(|_| {
                    malformed(format!("{letter}{digits}: `{digits}` is not a number"))
                })?),
            };
            if value.is_some_and(|v| !v.is_finite()) {
                return Err(malformed(format!("{letter}: the value is not finite")));
            }
            if words.iter().any(|(l, _)| *l == letter) {
                return Err(malformed(format!("{letter} given twice")));
            }
            words.push((letter, value));
            rest = number[end..].trim_start();
        }
        Ok(words)
    }
}

/// End of the command word: a letter and its number (`G1`, `M862.3`), or an extended command's
/// name (letters, digits and underscores, `SET_VELOCITY_LIMIT`).
fn command_end(code: &str) -> usize {
    let bytes = code.as_bytes();
    match bytes.first() {
        None => 0,
        Some(c) if c.is_ascii_alphabetic() => {
            let traditional = bytes.len() > 1 && (bytes[1].is_ascii_digit() || bytes[1] == b'.');
            let in_word = |b: &u8| {
                if traditional {
                    b.is_ascii_digit() || *b == b'.'
                } else {
                    b.is_ascii_alphanumeric() || *b == b'_'
                }
            };
            1 + bytes[1..].iter().take_while(|b| in_word(b)).count()
        }
        Some(_) => code.find(char::is_whitespace).unwrap_or(code.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_command_parameters_and_comment() {
        let line = Line::split("N12 g1x10.5 Y-3 E.02 F1800*71 ; move");
        assert_eq!(line.command, "G1");
        assert_eq!(line.comment, Some("move"));
        let words = line.parameters(1, "").unwrap();
        assert_eq!(
            words,
            vec![
                ('X', Some(10.5)),
                ('Y', Some(-3.0)),
                ('E', Some(0.02)),
                ('F', Some(1800.0))
            ]
        );
        let line = Line::split(";TYPE:External perimeter");
        assert_eq!(
            (line.command.as_str(), line.comment),
            ("", Some("TYPE:External perimeter"))
        );
        let line = Line::split("M862.3 P \"MK3S\" ; printer model");
        assert_eq!(line.command, "M862.3");
        let line = Line::split("SET_VELOCITY_LIMIT ACCEL=3000");
        assert_eq!(line.command, "SET_VELOCITY_LIMIT");
    }

    #[test]
    fn refuses_what_is_not_a_parameter() {
        for text in ["G1 X1.2.3", "G1 X1 X2", "G1 X1 /", "G1 X--1"] {
            let line = Line::split(text);
            assert!(
                matches!(
                    line.parameters(7, text),
                    Err(GcodeError::Malformed { line: 7, .. })
                ),
                "{text}"
            );
        }
        assert_eq!(
            Line::split("G28 X").parameters(1, "G28 X").unwrap(),
            vec![('X', None)]
        );
    }
}
