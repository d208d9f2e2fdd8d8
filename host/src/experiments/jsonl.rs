//! The files that keep an evaluation's finished cells: JSON lines, a header first (what the
//! cells depend on), then one cell a line, each written through to the disk as it is done. A
//! last line cut short by an interruption is dropped (and cut from the file before anything is
//! appended); any other line that does not read is an error that names it.

use std::io::{Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result};
use serde::Serialize;
use serde::de::DeserializeOwned;

/// A file's header and its whole records, read without changing it.
#[derive(Debug)]
pub struct Lines<H, R> {
    /// Line 1.
    pub header: H,
    /// Every whole record, with its line number (from 1).
    pub records: Vec<(usize, R)>,
    /// Bytes up to the end of the last whole line (0 when even the header was cut short).
    pub keep: usize,
}

/// Read the file at `path` (`what` names the command whose file it is, for errors): `None`
/// when there is none or it is empty.
pub fn read<H: DeserializeOwned, R: DeserializeOwned>(
    path: &Path,
    what: &str,
) -> Result<Option<Lines<H, R>>> {
    let shown = path.display();
    let text = match std::fs::read(path) {
        Ok(bytes) => String::from_utf8(bytes)
            .map_err(|_| anyhow::anyhow!("{shown} is not a text file of pushbot's"))?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("reading {shown}")),
    };
    if text.is_empty() {
        return Ok(None);
    }
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let header: H = serde_json::from_str(lines[0].trim_end())
        .with_context(|| format!("{shown} line 1 is not the header of a `{what}` file"))?;
    // A header without its newline was cut short before any record: it is written again.
    let mut keep = if lines[0].ends_with('\n') {
        lines[0].len()
    } else {
        0
    };
    let mut records = Vec::new();
    for (i, line) in lines.iter().enumerate().skip(1) {
        if i + 1 == lines.len() && !line.ends_with('\n') {
            tracing::warn!(
                "{shown}: its last line was cut short (an interrupted run); that cell runs again"
            );
            break;
        }
        let r: R = serde_json::from_str(line.trim_end())
            .with_context(|| format!("{shown} line {}", i + 1))?;
        keep += line.len();
        records.push((i + 1, r));
    }
    Ok(Some(Lines {
        header,
        records,
        keep,
    }))
}

/// Appends records to a file whose first `keep` bytes are whole lines (see [`read`]).
#[derive(Debug)]
pub struct Appender {
    path: PathBuf,
    file: Mutex<std::fs::File>,
}

impl Appender {
    /// Open `path` to append after its first `keep` bytes (what follows is cut); a file with
    /// nothing to keep gets `header` as its first line.
    pub fn open<H: Serialize>(path: &Path, keep: usize, header: &H) -> Result<Appender> {
        let shown = path.display();
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(path)
            .with_context(|| format!("opening {shown} to write"))?;
        file.set_len(keep as u64)
            .with_context(|| format!("cutting {shown}'s partial last line"))?;
        file.seek(std::io::SeekFrom::End(0))?;
        if keep == 0 {
            writeln!(file, "{}", serde_json::to_string(header)?)
                .with_context(|| format!("writing {shown}"))?;
            file.sync_data()?;
        }
        Ok(Appender {
            path: path.to_owned(),
            file: Mutex::new(file),
        })
    }

    /// Append one record (one line, written through to the disk).
    pub fn append<R: Serialize>(&self, record: &R) -> Result<()> {
        let line = serde_json::to_string(record)?;
        let mut f = self
            .file
            .lock()
            .map_err(|_| anyhow::anyhow!("{}: a writer panicked", self.path.display()))?;
        writeln!(f, "{line}")
            .and_then(|()| f.sync_data())
            .with_context(|| format!("writing {}", self.path.display()))
    }
}
