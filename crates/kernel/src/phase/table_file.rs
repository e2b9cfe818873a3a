//! Reading a phase table from a text file.

use std::path::Path;

use super::table::{validate, MAX_TABLE_ROWS};
use crate::error::{Error, Result};

/// Files larger than this are refused before reading: 1e6 rows of two
/// numbers with generous formatting and comments fit well within it.
const MAX_FILE_BYTES: u64 = 128 << 20;

/// The columns of a table file: one row per line, `cos(theta)` and value
/// separated by a comma or whitespace; `#` starts a comment; blank lines
/// are skipped. Errors name the file and, for a row, its line
/// (`FILE:LINE: what`), with the checks of `TabulatedPhase::new` applied
/// here so that they too name the line.
pub(super) fn read(path: &Path) -> Result<(Vec<f32>, Vec<f32>)> {
    let at = |line: usize, message: String| Error::format_at(path, line, message);
    let size = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    if size > MAX_FILE_BYTES {
        return Err(Error::format(
            path,
            format!("{size} bytes, more than a phase table may have ({MAX_FILE_BYTES})"),
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let (mut cos, mut values, mut lines) = (Vec::new(), Vec::new(), Vec::new());
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        if cos.len() == MAX_TABLE_ROWS {
            return Err(at(line, format!("more than {MAX_TABLE_ROWS} rows")));
        }
        let fields: Vec<&str> = if content.contains(',') {
            content.split(',').map(str::trim).collect()
        } else {
            content.split_whitespace().collect()
        };
        let [c, v] = fields[..] else {
            return Err(at(
                line,
                format!(
                    "expected two columns, cos(theta) and value; found {}",
                    fields.len()
                ),
            ));
        };
        let number = |s: &str| {
            s.parse::<f32>()
                .map_err(|_| at(line, format!("'{s}' is not a number")))
        };
        cos.push(number(c)?);
        values.push(number(v)?);
        lines.push(line);
    }
    match validate(&cos, &values) {
        Ok(()) => Ok((cos, values)),
        Err(e) => Err(match e.row {
            Some(row) => at(lines[row], e.message),
            None => Error::format(path, e.message),
        }),
    }
}
