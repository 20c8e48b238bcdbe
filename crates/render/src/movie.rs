//! Movies of [`Picture`]s: animated GIF and APNG in pure Rust, MP4 through `ffmpeg` when it
//! is on the PATH.
//!
//! A movie is written under a temporary name (`NAME.partial`) and renamed by
//! [`Movie::finish`], so an interrupted render never leaves a truncated movie that looks
//! complete.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use crate::{Picture, RenderError};

/// The container of a movie, from its file name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MovieKind {
    /// Animated GIF (256 colours per frame, every browser and slide program shows it).
    Gif,
    /// Animated PNG (full colour, lossless).
    Apng,
    /// H.264 in MP4, encoded by `ffmpeg`.
    Mp4,
}

impl MovieKind {
    /// The kind a file name asks for: `.gif`, `.apng` (or `.png`), `.mp4`.
    ///
    /// # Errors
    /// A message naming the file and the extensions that work.
    pub fn of(path: &Path) -> Result<Self, String> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_lowercase)
        {
            Some(e) if e == "gif" => Ok(Self::Gif),
            Some(e) if e == "apng" || e == "png" => Ok(Self::Apng),
            Some(e) if e == "mp4" => Ok(Self::Mp4),
            _ => Err(format!(
                "{}: a movie's name must end in .gif, .apng or .mp4",
                path.display()
            )),
        }
    }
}

enum Sink {
    Gif(gif::Encoder<BufWriter<File>>),
    Apng(png::Writer<BufWriter<File>>),
    Mp4(Child),
}

/// A movie being written, one [`Picture`] after another, all of one size.
pub struct Movie {
    sink: Sink,
    path: PathBuf,
    tmp: PathBuf,
    size: (u32, u32),
    fps: f64,
    frames: u32,
    pushed: u32,
}

impl std::fmt::Debug for Movie {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Movie")
            .field("path", &self.path)
            .field("size", &self.size)
            .field("frames", &self.frames)
            .finish()
    }
}

impl Movie {
    /// Starts a movie of `frames` pictures of `width × height` at `fps` frames per second.
    /// The kind follows the extension ([`MovieKind::of`]).
    ///
    /// # Errors
    /// [`RenderError::Draw`] for an unknown extension, a file that cannot be created, or an
    /// `.mp4` without `ffmpeg` on the PATH (with what to do instead).
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        frames: u32,
        fps: f64,
    ) -> Result<Self, RenderError> {
        let draw = |why: String| RenderError::Draw {
            path: path.to_path_buf(),
            why,
        };
        let kind = MovieKind::of(path).map_err(&draw)?;
        if !(fps.is_finite() && fps > 0.0 && fps <= 100.0) {
            return Err(draw(format!(
                "{fps} frames per second; use a rate from 0.1 to 100"
            )));
        }
        if frames == 0 {
            return Err(draw("a movie needs at least one frame".into()));
        }
        let name = path.file_name().map(|n| n.to_string_lossy().to_string());
        let tmp = path.with_file_name(format!("{}.partial", name.unwrap_or_default()));
        let file = || -> Result<BufWriter<File>, RenderError> {
            File::create(&tmp)
                .map(BufWriter::new)
                .map_err(|e| draw(e.to_string()))
        };
        let sink = match kind {
            MovieKind::Gif => {
                let (w, h) = (u16::try_from(width), u16::try_from(height));
                let (Ok(w), Ok(h)) = (w, h) else {
                    return Err(draw(format!(
                        "a GIF is at most 65535 pixels a side, not {width}×{height}; use --size"
                    )));
                };
                let mut enc =
                    gif::Encoder::new(file()?, w, h, &[]).map_err(|e| draw(e.to_string()))?;
                enc.set_repeat(gif::Repeat::Infinite)
                    .map_err(|e| draw(e.to_string()))?;
                Sink::Gif(enc)
            }
            MovieKind::Apng => {
                let mut enc = png::Encoder::new(file()?, width, height);
                enc.set_color(png::ColorType::Rgb);
                enc.set_depth(png::BitDepth::Eight);
                enc.set_compression(png::Compression::Fast);
                enc.set_animated(frames, 0)
                    .map_err(|e| draw(e.to_string()))?;
                let (num, den) = delay(fps);
                enc.set_frame_delay(num, den)
                    .map_err(|e| draw(e.to_string()))?;
                Sink::Apng(enc.write_header().map_err(|e| draw(e.to_string()))?)
            }
            MovieKind::Mp4 => {
                // H.264 in yuv420p needs even sides: pad by one pixel where odd.
                let child = Command::new("ffmpeg")
                    .args(["-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24"])
                    .args(["-s", &format!("{width}x{height}"), "-r", &format!("{fps}")])
                    .args(["-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white"])
                    .args(["-pix_fmt", "yuv420p", "-c:v", "libx264", "-f", "mp4"])
                    .arg(&tmp)
                    .stdin(Stdio::piped())
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .map_err(|e| {
                        if e.kind() == std::io::ErrorKind::NotFound {
                            draw("an .mp4 needs ffmpeg on the PATH, and there is none; install it (e.g. apt install ffmpeg) or write a .gif or .apng, which need nothing".into())
                        } else {
                            draw(format!("cannot start ffmpeg: {e}"))
                        }
                    })?;
                Sink::Mp4(child)
            }
        };
        Ok(Self {
            sink,
            path: path.to_path_buf(),
            tmp,
            size: (width, height),
            fps,
            frames,
            pushed: 0,
        })
    }

    fn err(&self, why: impl Into<String>) -> RenderError {
        RenderError::Draw {
            path: self.path.clone(),
            why: why.into(),
        }
    }

    /// Adds one picture.
    ///
    /// # Errors
    /// A picture of another size, more pictures than announced, or a write that fails.
    pub fn push(&mut self, pic: &Picture) -> Result<(), RenderError> {
        if (pic.width, pic.height) != self.size {
            return Err(self.err(format!(
                "a {}×{} picture in a {}×{} movie",
                pic.width, pic.height, self.size.0, self.size.1
            )));
        }
        if self.pushed == self.frames {
            return Err(self.err(format!("more than the {} frames announced", self.frames)));
        }
        let res = match &mut self.sink {
            Sink::Gif(enc) => {
                let mut frame = gif::Frame::from_rgb_speed(
                    self.size.0 as u16,
                    self.size.1 as u16,
                    &pic.rgb,
                    10,
                );
                frame.delay = (100.0 / self.fps).round().max(1.0) as u16;
                enc.write_frame(&frame).map_err(|e| e.to_string())
            }
            Sink::Apng(w) => w.write_image_data(&pic.rgb).map_err(|e| e.to_string()),
            Sink::Mp4(child) => match child.stdin.as_mut() {
                Some(stdin) => stdin
                    .write_all(&pic.rgb)
                    .map_err(|e| format!("ffmpeg stopped: {e}")),
                None => Err("ffmpeg has no input".into()),
            },
        };
        res.map_err(|why| self.err(why))?;
        self.pushed += 1;
        Ok(())
    }

    /// Finishes the file and gives it its name; returns the number of frames.
    ///
    /// # Errors
    /// Fewer pictures than announced, or a write or an encoder that fails.
    pub fn finish(self) -> Result<u32, RenderError> {
        if self.pushed != self.frames {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(self.err(format!(
                "{} of the {} frames announced",
                self.pushed, self.frames
            )));
        }
        let (path, tmp, pushed) = (self.path.clone(), self.tmp.clone(), self.pushed);
        let err = |why: String| RenderError::Draw {
            path: path.clone(),
            why,
        };
        match self.sink {
            Sink::Gif(enc) => enc
                .into_inner()
                .map_err(|e| e.to_string())
                .and_then(|mut f| f.flush().map_err(|e| e.to_string()))
                .map_err(err)?,
            Sink::Apng(w) => w.finish().map_err(|e| err(e.to_string()))?,
            Sink::Mp4(mut child) => {
                drop(child.stdin.take());
                let out = child
                    .wait_with_output()
                    .map_err(|e| err(format!("ffmpeg: {e}")))?;
                if !out.status.success() {
                    return Err(err(format!(
                        "ffmpeg failed ({}): {}",
                        out.status,
                        String::from_utf8_lossy(&out.stderr).trim()
                    )));
                }
            }
        }
        std::fs::rename(&tmp, &path).map_err(|e| err(e.to_string()))?;
        Ok(pushed)
    }
}

/// The frame delay `num/den` seconds of `fps`.
fn delay(fps: f64) -> (u16, u16) {
    let ms = (1000.0 / fps).round().clamp(1.0, 65535.0);
    (ms as u16, 1000)
}
