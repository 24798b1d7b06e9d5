//! PNG files written row by row (the png crate's stream writer): a report's
//! large images without holding them whole. Encoded at once, a failing 2048 x 2048 case's 16-bit PNG
//! took its samples (32 MiB), the encoder's big-endian copy of them and
//! the compressed output (60-100 MB in all) while the other images were
//! being encoded beside it.

use std::cell::RefCell;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use crate::fault::{Stop, maybe_stop};
use crate::io::{create_temp, parent_dir};
use crate::{ImageError, quantize8, quantize16};

/// The samples a [`PngFile`] stores per texel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PngKind {
    /// 16-bit RGBA (what [`crate::write_png16`] writes).
    Rgba16,
    /// 8-bit RGB: alpha dropped (for images whose every alpha is 1).
    Rgb8,
    /// 8-bit RGBA.
    Rgba8,
}

impl PngKind {
    /// Bytes per texel, and the PNG bit depth and colour type.
    fn layout(self) -> (usize, u8, u8) {
        match self {
            PngKind::Rgba16 => (8, 16, 6),
            PngKind::Rgb8 => (3, 8, 2),
            PngKind::Rgba8 => (4, 8, 6),
        }
    }
}

/// The file under the png crate's stream writer, keeping the first write
/// or flush error: the writer's end (IEND, the last flush) happens in its
/// `Drop`, which drops errors, and a short PNG must not be put in place.
struct Sink {
    out: BufWriter<std::fs::File>,
    error: Rc<RefCell<Option<std::io::Error>>>,
}

impl Sink {
    fn keep<T>(&self, r: std::io::Result<T>) -> std::io::Result<T> {
        if let Err(e) = &r {
            self.error.borrow_mut().get_or_insert_with(|| std::io::Error::new(e.kind(), e.to_string()));
        }
        r
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = self.out.write(buf);
        self.keep(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = self.out.flush();
        self.keep(r)
    }
}

impl Drop for Sink {
    fn drop(&mut self) {
        let r = self.out.flush();
        let _ = self.keep(r);
    }
}

/// Where a streamed write goes: a temp file renamed into place at the end
/// (or the file itself, under the fault plan's in-place writer), numbered
/// for fault injection ([`crate::fault`]).
struct Streamed {
    n: usize,
    temp: Option<tempfile::NamedTempFile>,
}

impl Streamed {
    /// Opens the write to `path`, through a 64 KiB buffer.
    fn open(path: &Path) -> Result<(Streamed, BufWriter<std::fs::File>), ImageError> {
        let io_err = |source| ImageError::Io { path: path.to_path_buf(), source };
        let n = crate::fault::next_write();
        let (temp, file) = match crate::fault::plan().plain_writer {
            true => (None, std::fs::File::create(path).map_err(io_err)?),
            false => {
                let temp = create_temp(&parent_dir(path), path).map_err(io_err)?;
                let file = temp.as_file().try_clone().map_err(io_err)?;
                (Some(temp), file)
            }
        };
        Ok((Streamed { n, temp }, BufWriter::with_capacity(1 << 16, file)))
    }

    /// Puts the file in place once its last byte is flushed.
    fn place(self, path: &Path) -> Result<(), ImageError> {
        maybe_stop(self.n, Stop::BeforeRename, path);
        if let Some(temp) = self.temp {
            temp.persist(path).map_err(|e| ImageError::Io { path: path.to_path_buf(), source: e.error })?;
        }
        maybe_stop(self.n, Stop::After, path);
        Ok(())
    }
}

/// A PNG file written one row at a time, replaced as
/// [`crate::atomic_replace`] replaces (a temp file renamed into place, no
/// sync): the png crate's stream writer, adaptive row filters and its fast
/// deflate, as rows come. It holds a row of samples and the encoder's
/// buffers, never the image.
pub struct PngFile {
    path: PathBuf,
    streamed: Streamed,
    stream: png::StreamWriter<'static, Sink>,
    error: Rc<RefCell<Option<std::io::Error>>>,
    kind: PngKind,
    width: u32,
    height: u32,
    rows: u32,
    samples: Vec<u8>,
}

impl PngFile {
    /// Starts `path` (`width` x `height` texels of `kind`), writing its header.
    pub fn create(path: &Path, width: u32, height: u32, kind: PngKind) -> Result<PngFile, ImageError> {
        let encode_err =
            |e: png::EncodingError| ImageError::Encode { path: path.to_path_buf(), format: "PNG", msg: e.to_string() };
        if width == 0 || height == 0 {
            let message = format!("cannot store an empty {width}x{height} image");
            return Err(ImageError::Encode { path: path.to_path_buf(), format: "PNG", msg: message });
        }
        let (streamed, out) = Streamed::open(path)?;
        let error = Rc::new(RefCell::new(None));
        let mut encoder = png::Encoder::new(Sink { out, error: error.clone() }, width, height);
        let (bpp, depth, colour) = kind.layout();
        encoder.set_depth(if depth == 16 { png::BitDepth::Sixteen } else { png::BitDepth::Eight });
        encoder.set_color(if colour == 2 { png::ColorType::Rgb } else { png::ColorType::Rgba });
        encoder.set_compression(png::Compression::Fast);
        encoder.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
        let stream = encoder.write_header().and_then(|w| w.into_stream_writer()).map_err(encode_err)?;
        Ok(PngFile {
            path: path.to_path_buf(),
            streamed,
            stream,
            error,
            kind,
            width,
            height,
            rows: 0,
            samples: Vec::with_capacity(width as usize * bpp),
        })
    }

    /// Appends the next row (`width` texels, clamped to [0, 1], NaN as 0).
    pub fn push_row(&mut self, row: &[[f32; 4]]) -> Result<(), ImageError> {
        assert_eq!(row.len(), self.width as usize, "a PNG row is the image's width");
        assert!(self.rows < self.height, "more rows than the PNG's height");
        let (bpp, _, _) = self.kind.layout();
        self.samples.resize(row.len() * bpp, 0);
        // Plain loops over sized buffers: iterator chains here were a fifth
        // of the report's time.
        match self.kind {
            PngKind::Rgba16 => {
                for (d, &v) in self.samples.chunks_exact_mut(2).zip(row.iter().flatten()) {
                    d.copy_from_slice(&quantize16(v).to_be_bytes());
                }
            }
            PngKind::Rgb8 => {
                for (d, p) in self.samples.chunks_exact_mut(3).zip(row) {
                    for (d, &v) in d.iter_mut().zip(p) {
                        *d = quantize8(v);
                    }
                }
            }
            PngKind::Rgba8 => {
                for (d, &v) in self.samples.iter_mut().zip(row.iter().flatten()) {
                    *d = quantize8(v);
                }
            }
        }
        self.stream.write_all(&self.samples).map_err(|source| ImageError::Io { path: self.path.clone(), source })?;
        self.rows += 1;
        if self.rows == self.height.div_ceil(2) {
            maybe_stop(self.streamed.n, Stop::Partial, &self.path);
        }
        Ok(())
    }

    /// Ends the file (every row pushed) and puts it in place.
    pub fn finish(self) -> Result<(), ImageError> {
        let path = self.path;
        assert_eq!(self.rows, self.height, "every row of the PNG pushed");
        let finished = self.stream.finish();
        // The stream's writer, and with it the file's last bytes, are gone now.
        if let Some(source) = self.error.borrow_mut().take() {
            return Err(ImageError::Io { path, source });
        }
        finished.map_err(|e| ImageError::Encode { path: path.clone(), format: "PNG", msg: e.to_string() })?;
        self.streamed.place(&path)
    }
}

/// Writes a file made by `write` as it goes, replaced as
/// [`crate::atomic_replace`] replaces (temp file and rename, no sync),
/// through a buffer: for report files too large to hold whole (a
/// 2048 x 2048 case's viewer data is 64 MiB of text).
pub fn atomic_replace_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), ImageError> {
    let io_err = |source| ImageError::Io { path: path.to_path_buf(), source };
    let (streamed, mut out) = Streamed::open(path)?;
    write(&mut out).map_err(io_err)?;
    out.flush().map_err(io_err)?;
    drop(out);
    maybe_stop(streamed.n, Stop::Partial, path);
    streamed.place(path)
}
