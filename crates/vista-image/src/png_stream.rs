//! PNG files written row by row: a report's large images without holding
//! them whole. Encoded at once, a failing 2048 x 2048 case's 16-bit PNG
//! took its samples (32 MiB), the encoder's big-endian copy of them and
//! the compressed output (60-100 MB in all) while the other images were
//! being encoded beside it.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::fault::{Stop, maybe_stop};
use crate::io::{RowFilter, create_temp, parent_dir, png_chunk, png_header};
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

/// Bytes of compressed data per IDAT chunk.
const IDAT_CHUNK: usize = 256 << 10;

/// Collects the zlib stream and writes it out as IDAT chunks.
struct Idat<W: Write> {
    out: W,
    pending: Vec<u8>,
}

impl<W: Write> Idat<W> {
    fn flush_chunks(&mut self, all: bool) -> std::io::Result<()> {
        while self.pending.len() >= IDAT_CHUNK || (all && !self.pending.is_empty()) {
            let n = self.pending.len().min(IDAT_CHUNK);
            let mut chunk = Vec::with_capacity(n + 12);
            png_chunk(&mut chunk, b"IDAT", &self.pending[..n]);
            self.out.write_all(&chunk)?;
            self.pending.drain(..n);
        }
        Ok(())
    }
}

impl<W: Write> Write for Idat<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.pending.extend_from_slice(buf);
        self.flush_chunks(false)?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
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
/// sync): rows filtered by least absolute sum and deflated by fdeflate (the
/// png crate's fast level) into IDAT chunks as they come. It holds two
/// rows of samples and at most one chunk of output.
pub struct PngFile {
    path: PathBuf,
    streamed: Streamed,
    deflate: fdeflate::Compressor<Idat<BufWriter<std::fs::File>>>,
    kind: PngKind,
    width: u32,
    height: u32,
    rows: u32,
    samples: Vec<u8>,
    previous: Vec<u8>,
    filter: RowFilter,
}

impl PngFile {
    /// Starts `path` (`width` x `height` texels of `kind`), writing its header.
    pub fn create(path: &Path, width: u32, height: u32, kind: PngKind) -> Result<PngFile, ImageError> {
        let io_err = |source| ImageError::Io { path: path.to_path_buf(), source };
        if width == 0 || height == 0 {
            let message = format!("cannot store an empty {width}x{height} image");
            return Err(ImageError::Encode { path: path.to_path_buf(), format: "PNG", msg: message });
        }
        let (streamed, mut out) = Streamed::open(path)?;
        let (bpp, depth, colour) = kind.layout();
        out.write_all(&png_header(width, height, depth, colour)).map_err(io_err)?;
        let deflate = fdeflate::Compressor::new(Idat { out, pending: Vec::new() }).map_err(io_err)?;
        let stride = width as usize * bpp;
        Ok(PngFile {
            path: path.to_path_buf(),
            streamed,
            deflate,
            kind,
            width,
            height,
            rows: 0,
            samples: Vec::with_capacity(stride),
            previous: vec![0; stride],
            filter: RowFilter::new(stride),
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
        let filter = self.filter.filter(&self.samples, &self.previous, bpp);
        let io_err = |source| ImageError::Io { path: self.path.clone(), source };
        self.deflate.write_data(&[filter]).map_err(io_err)?;
        self.deflate.write_data(self.filter.best()).map_err(io_err)?;
        std::mem::swap(&mut self.previous, &mut self.samples);
        self.rows += 1;
        if self.rows == self.height.div_ceil(2) {
            maybe_stop(self.streamed.n, Stop::Partial, &self.path);
        }
        Ok(())
    }

    /// Ends the file (every row pushed) and puts it in place.
    pub fn finish(self) -> Result<(), ImageError> {
        let path = self.path;
        let io_err = |source| ImageError::Io { path: path.clone(), source };
        assert_eq!(self.rows, self.height, "every row of the PNG pushed");
        let mut idat = self.deflate.finish().map_err(io_err)?;
        idat.flush_chunks(true).map_err(io_err)?;
        let mut end = Vec::with_capacity(12);
        png_chunk(&mut end, b"IEND", &[]);
        idat.out.write_all(&end).map_err(io_err)?;
        idat.out.flush().map_err(io_err)?;
        drop(idat);
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
