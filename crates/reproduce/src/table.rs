//! A CSV table with one header line, read by column name (the files this crate writes).

use std::path::{Path, PathBuf};

use study::SweepError;

/// The key values of a group of rows and the values of a column in them.
pub type Group = (Vec<String>, Vec<f64>);

/// A CSV table: a header and rows of fields.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// Where it was read from.
    pub path: PathBuf,
    /// The column names.
    pub header: Vec<String>,
    /// The rows.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// Reads a table.
    ///
    /// # Errors
    /// When the file cannot be read or has no header.
    pub fn read(path: &Path) -> Result<Self, SweepError> {
        let text = std::fs::read_to_string(path).map_err(|e| SweepError::Series {
            path: path.to_path_buf(),
            why: e.to_string(),
        })?;
        Self::parse(path, &text)
    }

    /// Parses the text of a table read from `path`.
    ///
    /// # Errors
    /// When it has no header.
    pub fn parse(path: &Path, text: &str) -> Result<Self, SweepError> {
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<String> = lines
            .next()
            .ok_or_else(|| SweepError::Series {
                path: path.to_path_buf(),
                why: "empty".into(),
            })?
            .split(',')
            .map(str::to_string)
            .collect();
        let rows = lines
            .filter(|l| !l.is_empty())
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect();
        Ok(Self {
            path: path.to_path_buf(),
            header,
            rows,
        })
    }

    /// The index of column `name`.
    ///
    /// # Errors
    /// When there is none.
    pub fn col(&self, name: &str) -> Result<usize, SweepError> {
        self.header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| SweepError::Series {
                path: self.path.clone(),
                why: format!("no column {name}"),
            })
    }

    /// Column `name` as numbers (NaN where a field does not parse).
    ///
    /// # Errors
    /// When there is no such column.
    pub fn f64s(&self, name: &str) -> Result<Vec<f64>, SweepError> {
        let c = self.col(name)?;
        Ok(self
            .rows
            .iter()
            .map(|r| r.get(c).and_then(|v| v.parse().ok()).unwrap_or(f64::NAN))
            .collect())
    }

    /// Column `name` as text.
    ///
    /// # Errors
    /// When there is no such column.
    pub fn strs(&self, name: &str) -> Result<Vec<String>, SweepError> {
        let c = self.col(name)?;
        Ok(self
            .rows
            .iter()
            .map(|r| r.get(c).cloned().unwrap_or_default())
            .collect())
    }

    /// The values of column `value` for every distinct combination of the columns `keys`, in
    /// order of first appearance: `(key values, values)`.
    ///
    /// # Errors
    /// When a column is missing.
    pub fn group(&self, keys: &[&str], value: &str) -> Result<Vec<Group>, SweepError> {
        let cols: Vec<usize> = keys.iter().map(|k| self.col(k)).collect::<Result<_, _>>()?;
        let v = self.f64s(value)?;
        let mut out: Vec<Group> = Vec::new();
        for (row, x) in self.rows.iter().zip(v) {
            let key: Vec<String> = cols
                .iter()
                .map(|&c| row.get(c).cloned().unwrap_or_default())
                .collect();
            match out.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.1.push(x),
                None => out.push((key, vec![x])),
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_keep_the_order_of_first_appearance() {
        let t = Table::parse(
            Path::new("s.csv"),
            "a,b,x\n1,p,10\n1,q,20\n2,p,30\n1,p,40\n",
        )
        .unwrap();
        let g = t.group(&["a", "b"], "x").unwrap();
        assert_eq!(g.len(), 3);
        assert_eq!(g[0], (vec!["1".into(), "p".into()], vec![10.0, 40.0]));
        assert_eq!(g[2].1, vec![30.0]);
        assert!(t.f64s("y").unwrap_err().to_string().contains("no column y"));
    }
}
