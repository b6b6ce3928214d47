//! Figures a test measures against a peer (glTF-IBL-Sampler, the glTF Sample Viewer) or an
//! exact reference, for the guide to include: the rows are collected as the test runs and,
//! only where `SPLITSUM_FIGURES` is set (`bash scripts/dev.sh figures`), written to
//! `book/src/figures/NAME.md` with the test that measured them, the date, the machine and
//! the commit. A test never compares the file with anything: the figure is a record of the
//! run, regenerated, not typed; the test's own assertions are its bounds.

use std::path::PathBuf;

/// One table of a test's figures.
pub struct Figure {
    name: String,
    test: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    notes: Vec<String>,
}

impl Figure {
    /// A figure `name` (its file name, without `.md`) measured by `test` (how to run it),
    /// with the columns `header`.
    pub fn new(name: &str, test: &str, header: &[&str]) -> Self {
        Figure { name: name.into(), test: test.into(), header: header.iter().map(|h| h.to_string()).collect(), rows: vec![], notes: vec![] }
    }

    /// A row of cells, one per column.
    pub fn row(&mut self, cells: Vec<String>) {
        assert_eq!(cells.len(), self.header.len(), "figure {}: a row of {} cells for {} columns", self.name, cells.len(), self.header.len());
        self.rows.push(cells);
    }

    /// Cell `column` of the row whose first cell is `first`, set to `value`.
    pub fn set(&mut self, first: &str, column: usize, value: String) {
        if let Some(r) = self.rows.iter_mut().find(|r| r[0] == first) {
            r[column] = value;
        }
    }

    /// A sentence below the table.
    pub fn note(&mut self, text: String) {
        self.notes.push(text);
    }

    /// Writes the figure where `SPLITSUM_FIGURES` is set; does nothing otherwise.
    pub fn write(&self) {
        if std::env::var_os("SPLITSUM_FIGURES").is_none() {
            return;
        }
        let mut md = format!("<!-- Written by `{}` with SPLITSUM_FIGURES=1 (bash scripts/dev.sh figures); regenerate it, do not edit it. -->\n\n", self.test);
        md += &splitsum_report::figures::markdown_table(&self.header, &self.rows);
        for n in &self.notes {
            md += &format!("\n{n}\n");
        }
        md += &format!("\nMeasured {}.\n", splitsum_report::figures::stamp());
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../book/src/figures").join(format!("{}.md", self.name));
        std::fs::write(&path, md).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
        eprintln!("wrote {}", path.display());
    }
}
