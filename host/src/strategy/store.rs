//! The pushing strategy on disk (Lau et al. §III-C/D collect it; this keeps it).
//!
//! A strategy file is plain UTF-8 text, one sample per line, so it can be appended and
//! flushed sample by sample and survives a crash mid-collection: a killed process loses at most
//! the sample it was writing (a last line without its newline, which loading drops and
//! appending cuts off). The format, version 1:
//!
//! ```text
//! pushbot-strategy 1
//! object <id>
//! columns p_x p_y r_x r_y s_x s_y theta
//! 0.061 -0.012 0.030 0.001 0.021 0.002 0.035
//! ...
//! ```
//!
//! Values are metres and radians in the object's frame at the start of each push (see
//! [`super::sample`]). Lines starting with `#` are comments.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::sample::Sample;

/// The first line of every strategy file, followed by the format version.
pub const MAGIC: &str = "pushbot-strategy";
/// The format version this code writes and reads.
pub const VERSION: u32 = 1;
const COLUMNS: &str = "columns p_x p_y r_x r_y s_x s_y theta";

/// Why a strategy file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a strategy file of a version this program reads, or is damaged.
    #[error("{path}:{line}: {what}")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// The file holds another object's strategy.
    #[error("{path}: holds the strategy of object `{found}`, not `{wanted}`")]
    WrongObject {
        /// The file.
        path: PathBuf,
        /// The object asked for.
        wanted: String,
        /// The object in the file.
        found: String,
    },
    /// An object id that cannot be written on one line.
    #[error("object id `{0}` must be non-empty and free of white space")]
    BadObjectId(String),
    /// A sample with a value that is not finite.
    #[error("sample has a value that is not finite: {0:?}")]
    NotFinite(Sample),
}

/// A loaded strategy file.
#[derive(Debug, Clone)]
pub struct StrategyFile {
    /// The object the strategy is for.
    pub object: String,
    /// The samples, in the order they were collected.
    pub samples: Vec<Sample>,
    /// Whether a partly written last sample (a crash mid-write) was dropped.
    pub dropped_partial: bool,
}

fn damaged(path: &Path, line: usize, what: impl Into<String>) -> StoreError {
    StoreError::Damaged {
        path: path.to_owned(),
        line,
        what: what.into(),
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> StoreError + '_ {
    move |source| StoreError::Io {
        path: path.to_owned(),
        source,
    }
}

/// Parse strategy text; `path` only names the file in errors.
pub fn parse(path: &Path, text: &str) -> Result<StrategyFile, StoreError> {
    let complete_len = text.rfind('\n').map_or(0, |i| i + 1);
    let dropped_partial = complete_len < text.len();
    let mut lines = text[..complete_len]
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.starts_with('#'));
    let (n, magic) = lines
        .next()
        .ok_or_else(|| damaged(path, 1, format!("empty: expected `{MAGIC} {VERSION}`")))?;
    match magic.split_whitespace().collect::<Vec<_>>().as_slice() {
        [m, v] if *m == MAGIC => match v.parse::<u32>() {
            Ok(VERSION) => {}
            Ok(other) => {
                return Err(damaged(
                    path,
                    n,
                    format!("format version {other}; this program reads version {VERSION}"),
                ));
            }
            Err(_) => return Err(damaged(path, n, format!("bad version `{v}`"))),
        },
        _ => {
            return Err(damaged(
                path,
                n,
                format!(
                    "not a pushing strategy file: expected `{MAGIC} {VERSION}`, found `{magic}`"
                ),
            ));
        }
    }
    let (n, obj) = lines
        .next()
        .ok_or_else(|| damaged(path, n + 1, "missing `object <id>` line"))?;
    let object = match obj.split_whitespace().collect::<Vec<_>>().as_slice() {
        ["object", id] => (*id).to_owned(),
        _ => {
            return Err(damaged(
                path,
                n,
                format!("expected `object <id>`, found `{obj}`"),
            ));
        }
    };
    let (n, cols) = lines
        .next()
        .ok_or_else(|| damaged(path, n + 1, "missing columns line"))?;
    if cols.split_whitespace().collect::<Vec<_>>() != COLUMNS.split_whitespace().collect::<Vec<_>>()
    {
        return Err(damaged(
            path,
            n,
            format!("expected `{COLUMNS}`, found `{cols}`"),
        ));
    }
    let mut samples = Vec::new();
    for (n, line) in lines {
        if line.is_empty() {
            continue;
        }
        let mut v = [0.0f64; 7];
        let mut fields = line.split_whitespace();
        for (i, slot) in v.iter_mut().enumerate() {
            let name = COLUMNS.split_whitespace().nth(i + 1).unwrap_or("value");
            let f = fields.next().ok_or_else(|| {
                damaged(path, n, format!("missing {name} (a sample has 7 values)"))
            })?;
            *slot = f
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| damaged(path, n, format!("{name} is `{f}`, not a finite number")))?;
        }
        if fields.next().is_some() {
            return Err(damaged(path, n, "more than 7 values"));
        }
        samples.push(Sample {
            p: [v[0], v[1]],
            r: [v[2], v[3]],
            s: [v[4], v[5]],
            theta: v[6],
        });
    }
    Ok(StrategyFile {
        object,
        samples,
        dropped_partial,
    })
}

/// Load a strategy file.
pub fn load(path: &Path) -> Result<StrategyFile, StoreError> {
    let mut text = String::new();
    File::open(path)
        .and_then(|mut f| f.read_to_string(&mut text))
        .map_err(io(path))?;
    parse(path, &text)
}

/// Appends samples to a strategy file, each written and flushed to the disk on its own.
#[derive(Debug)]
pub struct StrategyWriter {
    path: PathBuf,
    file: File,
}

impl StrategyWriter {
    /// Open `path` for appending samples of `object`, creating it with a header when it does not
    /// exist. An existing file must be a valid strategy of the same object; a partly written last
    /// sample left by a crash is cut off first. Returns the writer and the samples already there.
    pub fn open(path: &Path, object: &str) -> Result<(StrategyWriter, Vec<Sample>), StoreError> {
        if object.is_empty() || object.chars().any(char::is_whitespace) {
            return Err(StoreError::BadObjectId(object.to_owned()));
        }
        let mut file = OpenOptions::new()
            .read(true)
            .append(true)
            .create(true)
            .open(path)
            .map_err(io(path))?;
        let mut text = String::new();
        file.read_to_string(&mut text).map_err(io(path))?;
        let samples = if text.is_empty() {
            file.write_all(format!("{MAGIC} {VERSION}\nobject {object}\n{COLUMNS}\n").as_bytes())
                .map_err(io(path))?;
            file.sync_data().map_err(io(path))?;
            Vec::new()
        } else {
            let parsed = parse(path, &text)?;
            if parsed.object != object {
                return Err(StoreError::WrongObject {
                    path: path.to_owned(),
                    wanted: object.to_owned(),
                    found: parsed.object,
                });
            }
            if parsed.dropped_partial {
                let keep = text.rfind('\n').map_or(0, |i| i + 1) as u64;
                file.set_len(keep).map_err(io(path))?;
                file.seek(SeekFrom::End(0)).map_err(io(path))?;
            }
            parsed.samples
        };
        Ok((
            StrategyWriter {
                path: path.to_owned(),
                file,
            },
            samples,
        ))
    }

    /// Append one sample and flush it to the disk.
    pub fn append(&mut self, s: &Sample) -> Result<(), StoreError> {
        if !s.is_finite() {
            return Err(StoreError::NotFinite(*s));
        }
        // `{:?}` prints the shortest text that parses back to the same f64.
        let line = format!(
            "{:?} {:?} {:?} {:?} {:?} {:?} {:?}\n",
            s.p[0], s.p[1], s.r[0], s.r[1], s.s[0], s.s[1], s.theta
        );
        self.file
            .write_all(line.as_bytes())
            .map_err(io(&self.path))?;
        self.file.sync_data().map_err(io(&self.path))
    }

    /// The file written to.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(i: usize) -> Sample {
        let f = i as f64;
        Sample {
            p: [0.01 * f, -0.02],
            r: [0.03, 1e-17 * f],
            s: [0.1 / 3.0, f],
            theta: -0.5,
        }
    }

    #[test]
    fn samples_round_trip_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("obj.strategy");
        let (mut w, old) = StrategyWriter::open(&path, "snake").unwrap();
        assert!(old.is_empty());
        for i in 0..50 {
            w.append(&sample(i)).unwrap();
        }
        drop(w);
        let f = load(&path).unwrap();
        assert_eq!(f.object, "snake");
        assert!(!f.dropped_partial);
        assert_eq!(f.samples, (0..50).map(sample).collect::<Vec<_>>());
        // Re-opening appends after what is there.
        let (mut w, old) = StrategyWriter::open(&path, "snake").unwrap();
        assert_eq!(old.len(), 50);
        w.append(&sample(50)).unwrap();
        assert_eq!(load(&path).unwrap().samples.len(), 51);
    }

    #[test]
    fn a_crash_mid_sample_loses_only_that_sample() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("obj.strategy");
        let (mut w, _) = StrategyWriter::open(&path, "L").unwrap();
        for i in 0..10 {
            w.append(&sample(i)).unwrap();
        }
        drop(w);
        // A write cut off half way through a line, as a killed process leaves it.
        let mut f = OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(b"0.5 0.25 0.1").unwrap();
        drop(f);
        let loaded = load(&path).unwrap();
        assert_eq!(loaded.samples.len(), 10);
        assert!(loaded.dropped_partial);
        // Appending after the crash cuts the fragment off instead of gluing onto it.
        let (mut w, old) = StrategyWriter::open(&path, "L").unwrap();
        assert_eq!(old.len(), 10);
        w.append(&sample(10)).unwrap();
        let loaded = load(&path).unwrap();
        assert_eq!(loaded.samples, (0..11).map(sample).collect::<Vec<_>>());
        assert!(!loaded.dropped_partial);
    }

    #[test]
    fn damage_is_reported_with_line_and_field() {
        let p = Path::new("x.strategy");
        let head = format!("{MAGIC} 1\nobject a\n{COLUMNS}\n");
        let e = parse(p, &format!("{head}1 2 3 4 5 6 7\n1 2 3 x 5 6 7\n"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x.strategy:5") && e.contains("r_y") && e.contains("`x`"),
            "{e}"
        );
        let e = parse(p, &format!("{head}1 2 3 4 5 6\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(":4") && e.contains("missing theta"), "{e}");
        let e = parse(p, &format!("{head}1 2 3 4 5 6 7 8\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 7"), "{e}");
        let e = parse(p, &format!("{head}1 2 3 4 5 6 NaN\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a finite number"), "{e}");
        let e = parse(p, "pushbot-strategy 2\nobject a\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("version 2"), "{e}");
        let e = parse(p, "hello\n").unwrap_err().to_string();
        assert!(
            e.contains(":1") && e.contains("not a pushing strategy"),
            "{e}"
        );
        let e = parse(p, "").unwrap_err().to_string();
        assert!(e.contains("empty"), "{e}");
    }

    #[test]
    fn another_objects_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s");
        StrategyWriter::open(&path, "snake").unwrap();
        let e = StrategyWriter::open(&path, "scissors")
            .unwrap_err()
            .to_string();
        assert!(e.contains("snake") && e.contains("scissors"), "{e}");
        assert!(StrategyWriter::open(&path, "two words").is_err());
    }

    #[test]
    fn non_finite_samples_are_not_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s");
        let (mut w, _) = StrategyWriter::open(&path, "o").unwrap();
        let mut s = sample(1);
        s.theta = f64::NAN;
        assert!(w.append(&s).is_err());
        assert!(load(&path).unwrap().samples.is_empty());
    }
}
