//! A recording's CSV file as numbers (`docs/measured.md` 1.1): one header row of names, then
//! one row of numbers per sample. Every cell is checked before anything is used.

use std::path::Path;

use crate::error::MeasuredError;

/// A numeric CSV table: its header and its columns.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvTable {
    /// The header's names, trimmed, in file order.
    pub header: Vec<String>,
    /// One vector per header column, one value per data row.
    pub columns: Vec<Vec<f64>>,
    /// The file line of each data row (1-based; the header is line 1 unless comments precede it).
    pub lines: Vec<u64>,
}

impl CsvTable {
    /// Read `path`: lines starting with `#` are comments; every cell must be a finite number.
    /// Errors name the file and the row, line and column.
    pub fn read(path: &Path) -> Result<Self, MeasuredError> {
        let mut rd = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .flexible(true)
            .from_path(path)
            .map_err(|e| MeasuredError::file(path, format!("cannot read: {e}")))?;
        let header: Vec<String> = rd
            .headers()
            .map_err(|e| MeasuredError::file(path, format!("cannot read the header: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        check_header(path, &header)?;
        let mut table = CsvTable {
            columns: vec![Vec::new(); header.len()],
            header,
            lines: Vec::new(),
        };
        for (k, record) in rd.records().enumerate() {
            let record = record.map_err(|e| MeasuredError::Row {
                file: path.to_path_buf(),
                row: k + 1,
                line: e.position().map_or(0, |p| p.line()),
                reason: format!("cannot read: {e}"),
            })?;
            table.push(path, k + 1, &record)?;
        }
        Ok(table)
    }

    /// The column named `name`, if any.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        let k = self.header.iter().position(|h| h == name)?;
        Some(&self.columns[k])
    }

    /// Append data row `row` (1-based) after checking its width and every cell.
    fn push(&mut self, path: &Path, row: usize, record: &csv::StringRecord) -> Result<(), MeasuredError> {
        let line = record.position().map_or(0, |p| p.line());
        if record.len() != self.header.len() {
            return Err(MeasuredError::Row {
                file: path.to_path_buf(),
                row,
                line,
                reason: format!(
                    "{} cells, but the header has {} columns",
                    record.len(),
                    self.header.len()
                ),
            });
        }
        for (k, cell) in record.iter().enumerate() {
            let value = parse_cell(cell).map_err(|reason| MeasuredError::Cell {
                file: path.to_path_buf(),
                row,
                line,
                column: self.header[k].clone(),
                reason,
            })?;
            self.columns[k].push(value);
        }
        self.lines.push(line);
        Ok(())
    }
}

/// A header of non-empty, distinct names.
fn check_header(path: &Path, header: &[String]) -> Result<(), MeasuredError> {
    if header.iter().all(String::is_empty) {
        return Err(MeasuredError::file(
            path,
            "no header row (the first line names the columns)",
        ));
    }
    if let Some(k) = header.iter().position(String::is_empty) {
        return Err(MeasuredError::file(
            path,
            format!("the header's column {} has no name", k + 1),
        ));
    }
    for (k, h) in header.iter().enumerate() {
        if header[..k].contains(h) {
            return Err(MeasuredError::column(path, h, "named twice in the header"));
        }
    }
    Ok(())
}

/// One cell as a finite number, or why not.
fn parse_cell(cell: &str) -> Result<f64, String> {
    if cell.is_empty() {
        return Err("empty cell".into());
    }
    let v: f64 = cell.parse().map_err(|_| format!("{cell:?} is not a number"))?;
    if !v.is_finite() {
        return Err(format!("{cell:?} is not a finite number"));
    }
    Ok(v)
}
