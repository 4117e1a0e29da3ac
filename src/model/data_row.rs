//! Where a row of data is, as every report names it: `row 10 (line 12)`.
//!
//! - **row**: the row among the rows a command read, counted from 1 in the
//!   order given (a file's data rows in file order; an array's rows). Rows a
//!   loader rejects (a RecurDyn log's duplicates, ...) are named by their
//!   line alone and not counted.
//! - **line**: the row's line in its file, counted from 1 with the header,
//!   comments and blank lines; none for data that never were a file (the
//!   Python package's arrays).
//!
//! Cables are counted from 1 too (`encoder of cable 4`). The JSON of every
//! command names a row by the fields `row` and `line` (`null` without a
//! file), and a cable by `cable`.
//!
//! ```
//! use sagcal::model::DataRow;
//! // The 10th data row of a file, on its line 12 (a comment and the header above it).
//! let row = DataRow::at(9, 12);
//! assert_eq!((row.row, row.line), (10, Some(12)));
//! assert_eq!(row.to_string(), "row 10 (line 12)");
//! // Data given as an array (line 0: no file).
//! assert_eq!(DataRow::at(9, 0).to_string(), "row 10");
//! assert_eq!(serde_json::to_value(DataRow::at(9, 0)).unwrap(), serde_json::json!({"row": 10, "line": null}));
//! ```

use serde::Serialize;

/// A row of data: its place among the rows read and its line in its file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct DataRow {
    /// The row, counted from 1 among the rows read, in the order given.
    pub row: usize,
    /// Its line in the file (from 1, every line counted); `None` for data
    /// that were not read from a file.
    pub line: Option<usize>,
}

impl DataRow {
    /// The row of 0-based `index` among the rows read, on line `line` of its
    /// file (0: not from a file, as [`crate::model::PoseMeasurement::line`]).
    pub fn at(index: usize, line: usize) -> Self {
        DataRow {
            row: index + 1,
            line: (line > 0).then_some(line),
        }
    }
}

/// `row 10 (line 12)`, or `row 10` without a file.
impl std::fmt::Display for DataRow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(line) => write!(f, "row {} (line {line})", self.row),
            None => write!(f, "row {}", self.row),
        }
    }
}
