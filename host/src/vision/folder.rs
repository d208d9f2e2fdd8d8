//! A folder of image files as a frame source: PNG or JPEG files in name order, converted to
//! grayscale. A frame's time is read from a sidecar `NAME.json` with a `time` field (as the sim
//! camera writes with `--frames DIR`), else it is `index / fps`.

use std::path::{Path, PathBuf};

use super::frame::{Frame, FrameSource, SourceError};

/// Frames from image files.
#[derive(Debug)]
pub struct FolderSource {
    dir: PathBuf,
    files: Vec<PathBuf>,
    next: usize,
    fps: f64,
}

impl FolderSource {
    /// List the images in `dir`; an empty or missing folder is an error.
    pub fn open(dir: &Path, fps: f64) -> Result<FolderSource, SourceError> {
        let entries = std::fs::read_dir(dir).map_err(|e| {
            SourceError::BadSource(format!("cannot read image folder {}: {e}", dir.display()))
        })?;
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                    let e = e.to_ascii_lowercase();
                    e == "png" || e == "jpg" || e == "jpeg"
                })
            })
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(SourceError::BadSource(format!(
                "image folder {} has no .png or .jpg files",
                dir.display()
            )));
        }
        if !(fps > 0.0 && fps.is_finite()) {
            return Err(SourceError::BadSource(format!(
                "frame rate {fps} must be positive"
            )));
        }
        Ok(FolderSource {
            dir: dir.to_path_buf(),
            files,
            next: 0,
            fps,
        })
    }
}

impl FolderSource {
    /// The image files, in the order their frames come (frame `seq` is file `seq`).
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }
}

#[derive(serde::Deserialize)]
struct Sidecar {
    time: f64,
}

impl FrameSource for FolderSource {
    fn describe(&self) -> String {
        format!(
            "folder {} ({} images)",
            self.dir.display(),
            self.files.len()
        )
    }

    fn next_frame(&mut self) -> Result<Option<Frame>, SourceError> {
        let Some(path) = self.files.get(self.next).cloned() else {
            return Ok(None);
        };
        let index = self.next;
        self.next += 1;
        let img = image::open(&path)
            .map_err(|e| SourceError::BadFrame(format!("{}: {e}", path.display())))?;
        let gray = img.into_luma8();
        let (width, height) = gray.dimensions();
        let time = std::fs::read_to_string(path.with_extension("json"))
            .ok()
            .and_then(|t| serde_json::from_str::<Sidecar>(&t).ok())
            .map(|s| s.time)
            .filter(|t| t.is_finite())
            .unwrap_or(index as f64 / self.fps);
        Ok(Some(Frame {
            seq: index as u64,
            time,
            width,
            height,
            pixels: gray.into_raw(),
        }))
    }
}
