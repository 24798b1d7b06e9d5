//! PNG16 / EXR round trips, error reporting and atomic writes.

use std::path::Path;

use vista_image::{Image, ImageError, atomic_write, load, read_exr, read_png16, save, write_exr, write_png16};

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn dir_entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

fn gradient(w: u32, h: u32) -> Image {
    Image::from_fn(w, h, |x, y| {
        let u = x as f32 / (w - 1) as f32;
        let v = y as f32 / (h - 1) as f32;
        [u, v, (u * 7.3 + v * 2.1).fract(), 1.0 - 0.5 * u]
    })
}

#[test]
fn png16_round_trip_within_half_a_step() {
    let dir = tempdir();
    let path = dir.path().join("g.png");
    let img = gradient(37, 21);
    write_png16(&path, &img).unwrap();
    let back = read_png16(&path).unwrap();
    assert_eq!(back.dimensions(), (37, 21));
    for (p, q) in img.data.iter().zip(&back.data) {
        for c in 0..4 {
            let err = (p[c] - q[c]).abs();
            assert!(err <= 0.5 / 65535.0 + 1e-7, "{} vs {} (err {err})", p[c], q[c]);
            // Read values sit exactly on the 16-bit grid.
            let level = q[c] * 65535.0;
            assert!((level - level.round()).abs() < 1e-3);
        }
    }
    // Writing what was read reproduces the file byte for byte.
    let again = dir.path().join("again.png");
    write_png16(&again, &back).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn png16_levels_are_exact_and_out_of_range_is_clamped() {
    let dir = tempdir();
    let path = dir.path().join("levels.png");
    let levels = [0u16, 1, 2, 255, 256, 32767, 32768, 65534, 65535];
    let mut img = Image::from_fn(levels.len() as u32, 2, |x, _| {
        let v = f32::from(levels[x as usize]) / 65535.0;
        [v, v, v, v]
    });
    img.set(0, 1, [-0.5, 2.0, f32::NAN, f32::INFINITY]);
    img.set(1, 1, [f32::NEG_INFINITY, 1.0 + 1e-6, -0.0, 0.5]);
    write_png16(&path, &img).unwrap();
    let back = read_png16(&path).unwrap();
    for (x, &l) in levels.iter().enumerate() {
        let q = back.get(x as u32, 0).map(|v| (v * 65535.0).round() as u16);
        assert_eq!(q, [l; 4]);
    }
    assert_eq!(back.get(0, 1), [0.0, 1.0, 0.0, 1.0]);
    assert_eq!(back.get(1, 1)[..3], [0.0, 1.0, 0.0]);
    assert_eq!((back.get(1, 1)[3] * 65535.0).round(), 32768.0); // round(0.5 * 65535)
}

#[test]
fn reads_8_bit_rgb_and_grey_png() {
    let dir = tempdir();
    let rgb_path = dir.path().join("rgb8.png");
    let rgb = image::RgbImage::from_fn(3, 2, |x, y| image::Rgb([x as u8 * 100, y as u8 * 255, 17]));
    rgb.save(&rgb_path).unwrap();
    let img = read_png16(&rgb_path).unwrap();
    assert_eq!(img.dimensions(), (3, 2));
    assert_eq!(img.get(2, 1), [200.0 / 255.0, 1.0, 17.0 / 255.0, 1.0]);
    assert_eq!(img.get(0, 0), [0.0, 0.0, 17.0 / 255.0, 1.0]);

    let grey_path = dir.path().join("grey8.png");
    image::GrayImage::from_fn(2, 2, |x, _| image::Luma([x as u8 * 51])).save(&grey_path).unwrap();
    let img = read_png16(&grey_path).unwrap();
    assert_eq!(img.get(1, 0), [0.2, 0.2, 0.2, 1.0]);
}

#[test]
fn exr_round_trip_is_bit_exact() {
    let dir = tempdir();
    let path = dir.path().join("hdr.exr");
    let specials = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -0.0,
        -3.5,
        1e30,
        1e-40,                       // subnormal
        f32::from_bits(0x7fc0_1234), // NaN with payload
    ];
    let img = Image::from_fn(19, 7, |x, y| {
        let i = (x + 19 * y) as usize;
        [specials[i % specials.len()], x as f32 * 0.1 - 0.7, (y as f32).exp(), 1.0 / (1.0 + i as f32)]
    });
    write_exr(&path, &img).unwrap();
    let back = read_exr(&path).unwrap();
    assert!(back.bit_identical(&img));
    assert_eq!(back.content_hash(), img.content_hash());
}

#[test]
fn exr_without_alpha_reads_alpha_one() {
    let dir = tempdir();
    let path = dir.path().join("rgb.exr");
    exr::prelude::write_rgb_file(&path, 4, 3, |x, y| (x as f32, y as f32, -1.0f32)).unwrap();
    let img = read_exr(&path).unwrap();
    assert_eq!(img.dimensions(), (4, 3));
    assert_eq!(img.get(3, 2), [3.0, 2.0, -1.0, 1.0]);
}

#[test]
fn corrupt_files_give_decode_errors_naming_the_path() {
    let dir = tempdir();
    let png = dir.path().join("corrupt.png");
    std::fs::write(&png, b"definitely not a png").unwrap();
    let err = read_png16(&png).unwrap_err();
    assert!(matches!(err, ImageError::Decode { format: "PNG", .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains(&png.display().to_string()), "{msg}");
    assert!(msg.contains("is not a valid PNG"), "{msg}");

    // A truncated but otherwise genuine PNG.
    let good = dir.path().join("good.png");
    write_png16(&good, &gradient(32, 32)).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let truncated = dir.path().join("truncated.png");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    assert!(matches!(read_png16(&truncated), Err(ImageError::Decode { .. })));

    let exr = dir.path().join("corrupt.exr");
    std::fs::write(&exr, b"\x76\x2f\x31\x01garbage").unwrap();
    let err = read_exr(&exr).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains(&exr.display().to_string()) && msg.contains("is not a valid EXR"), "{msg}");

    // A PNG is not an EXR.
    assert!(matches!(read_exr(&good), Err(ImageError::Decode { format: "EXR", .. })));
}

#[test]
fn missing_file_is_an_io_error_naming_the_path() {
    let dir = tempdir();
    let path = dir.path().join("missing.png");
    let err = read_png16(&path).unwrap_err();
    match &err {
        ImageError::Io { path: p, source } => {
            assert_eq!(p, &path);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected Io, got {other:?}"),
    }
    assert!(err.to_string().contains("missing.png"));
}

#[test]
fn save_and_load_dispatch_on_extension() {
    let dir = tempdir();
    let img = gradient(9, 5);
    for name in ["a.png", "b.PNG", "c.exr", "d.Exr"] {
        let path = dir.path().join(name);
        save(&path, &img).unwrap();
        let back = load(&path).unwrap();
        assert_eq!(back.dimensions(), (9, 5));
        if name.to_lowercase().ends_with(".exr") {
            assert!(back.bit_identical(&img), "{name}");
        }
    }
    // The PNG really is a PNG and the EXR an EXR.
    assert!(read_png16(&dir.path().join("b.PNG")).is_ok());
    assert!(read_exr(&dir.path().join("d.Exr")).is_ok());

    for name in ["e.jpg", "noext"] {
        let path = dir.path().join(name);
        let err = save(&path, &img).unwrap_err();
        assert!(matches!(err, ImageError::UnsupportedExtension { .. }));
        let msg = err.to_string();
        assert!(msg.contains(name) && msg.contains(".png") && msg.contains(".exr"), "{msg}");
        assert!(matches!(load(&path), Err(ImageError::UnsupportedExtension { .. })));
    }
    assert!(!dir.path().join("e.jpg").exists());
}

#[test]
fn atomic_write_replaces_content_and_leaves_no_temp_files() {
    let dir = tempdir();
    let path = dir.path().join("out.bin");
    atomic_write(&path, b"first version, rather long").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"first version, rather long");
    atomic_write(&path, b"second").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second");
    write_png16(&dir.path().join("img.png"), &gradient(4, 4)).unwrap();
    write_exr(&dir.path().join("img.exr"), &gradient(4, 4)).unwrap();
    assert_eq!(dir_entries(dir.path()), ["img.exr", "img.png", "out.bin"]);
}

#[test]
fn atomic_write_failure_keeps_old_file_and_cleans_up() {
    let dir = tempdir();
    // Target is a non-empty directory: the final rename must fail.
    let target = dir.path().join("occupied");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"x").unwrap();
    let err = atomic_write(&target, b"data").unwrap_err();
    assert!(matches!(err, ImageError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("occupied"));
    assert_eq!(dir_entries(dir.path()), ["occupied"]);
    assert_eq!(dir_entries(&target), ["keep"]);

    // Missing parent directory.
    let nowhere = dir.path().join("no/such/dir/x.png");
    let err = write_png16(&nowhere, &gradient(2, 2)).unwrap_err();
    assert!(matches!(err, ImageError::Io { .. }));
    assert!(err.to_string().contains("x.png"));
}

#[test]
fn encoding_an_empty_image_is_an_error_not_a_panic() {
    let dir = tempdir();
    let path = dir.path().join("empty.png");
    let err = write_png16(&path, &Image::new(0, 0)).unwrap_err();
    assert!(matches!(err, ImageError::Encode { .. }), "{err:?}");
    assert!(!path.exists());
    let exr = dir.path().join("empty.exr");
    let err = write_exr(&exr, &Image::new(0, 3)).unwrap_err();
    assert!(matches!(err, ImageError::Encode { format: "EXR", .. }), "{err:?}");
    assert!(dir_entries(dir.path()).is_empty());
}

/// The goldens' encoding keeps every 16-bit value: RGB where alpha is 1
/// everywhere, RGBA otherwise, and fewer bytes than the report's encoding.
#[test]
fn small_png16_is_lossless_and_smaller() {
    let p = std::path::Path::new("g.png");
    let img = Image::from_fn(64, 48, |x, y| [x as f32 / 63.0, y as f32 / 47.0, ((x * y) % 7) as f32 / 6.0, 1.0]);
    let small = vista_image::encode_png16_small(p, &img).unwrap();
    let plain = vista_image::encode_png16(p, &img).unwrap();
    assert!(small.len() < plain.len(), "{} vs {} bytes", small.len(), plain.len());
    let back = vista_image::decode_png16(p, &small).unwrap();
    let again = vista_image::decode_png16(p, &plain).unwrap();
    assert!(back.bit_identical(&again), "the same values as the plain encoding");
    // A translucent pixel keeps the alpha channel.
    let mut t = img.clone();
    t.set(3, 4, [0.5, 0.5, 0.5, 0.25]);
    let back = vista_image::decode_png16(p, &vista_image::encode_png16_small(p, &t).unwrap()).unwrap();
    assert_eq!(back.get(3, 4)[3], vista_image::quantize16(0.25) as f32 / 65535.0);
}

#[test]
fn small_png8_keeps_the_8_bit_values_in_the_fewest_channels() {
    let dir = tempdir();
    // PNG colour type (IHDR byte 25): 0 grey, 2 RGB, 4 grey + alpha, 6 RGBA.
    let colour_type = |path: &Path| std::fs::read(path).unwrap()[25];
    let noise = |x: u32, y: u32| ((x * 7919 + y * 104_729) % 251) as f32 / 250.0;
    let grey = Image::from_fn(32, 32, |x, y| {
        let v = noise(x, y);
        [v, v, v, 1.0]
    });
    let mut coloured = grey.clone();
    coloured.set(5, 6, [0.2, 0.4, 0.6, 1.0]);
    let mut grey_translucent = grey.clone();
    grey_translucent.set(1, 2, [0.5, 0.5, 0.5, 0.5]);
    let mut translucent = coloured.clone();
    translucent.set(1, 2, [0.1, 0.5, 0.9, 0.5]);
    for (name, img, ty) in
        [("grey", &grey, 0), ("rgb", &coloured, 2), ("grey_alpha", &grey_translucent, 4), ("rgba", &translucent, 6)]
    {
        let small = dir.path().join(format!("{name}-small.png"));
        let plain = dir.path().join(format!("{name}-plain.png"));
        vista_image::write_png8_small(&small, img).unwrap();
        vista_image::write_png8(&plain, img).unwrap();
        assert_eq!(colour_type(&small), ty, "{name}");
        let (a, b) = (read_png16(&small).unwrap(), read_png16(&plain).unwrap());
        assert!(a.bit_identical(&b), "{name}: the same 8-bit values as write_png8");
        let (ls, lp) = (std::fs::metadata(&small).unwrap().len(), std::fs::metadata(&plain).unwrap().len());
        assert!(ls < lp, "{name}: {ls} bytes, not fewer than {lp}");
    }
    // A grey 32 x 32 noise thumbnail fits in well under half the RGB bytes.
    let bytes = std::fs::metadata(dir.path().join("grey-small.png")).unwrap().len();
    assert!(bytes < 1200, "{bytes} bytes");
}

#[test]
fn png_files_written_row_by_row_hold_what_the_whole_image_writers_hold() {
    use vista_image::{PngFile, PngKind};
    let dir = tempdir();
    // Noise: 512 x 300 16-bit RGBA deflates to several 256 KiB IDAT chunks.
    let noise = |x: u32, y: u32, c: u32| ((x * 7919 + y * 104_729 + c * 31) % 1009) as f32 / 1008.0;
    let img = Image::from_fn(512, 300, |x, y| [noise(x, y, 0), noise(x, y, 1), noise(x, y, 2), noise(x, y, 3)]);
    let mut opaque = img.clone();
    opaque.data.iter_mut().for_each(|p| p[3] = 1.0);
    for (name, kind, source) in
        [("a16.png", PngKind::Rgba16, &img), ("a8.png", PngKind::Rgba8, &img), ("o8.png", PngKind::Rgb8, &opaque)]
    {
        let path = dir.path().join(name);
        let mut png = PngFile::create(&path, source.width, source.height, kind).unwrap();
        for row in source.data.chunks(source.width as usize) {
            png.push_row(row).unwrap();
        }
        png.finish().unwrap();
        let whole = dir.path().join(format!("whole-{name}"));
        match kind {
            PngKind::Rgba16 => write_png16(&whole, source).unwrap(),
            _ => vista_image::write_png8(&whole, source).unwrap(),
        }
        let (streamed, whole) = (read_png16(&path).unwrap(), read_png16(&whole).unwrap());
        assert!(streamed.bit_identical(&whole), "{name}: the same values as the whole-image writer");
    }
    let bytes = std::fs::read(dir.path().join("a16.png")).unwrap();
    let idats = bytes.windows(4).filter(|w| w == b"IDAT").count();
    assert!(idats > 1, "{idats} IDAT chunk(s): the chunking is not exercised");
    assert_eq!(dir_entries(dir.path()).len(), 6, "no temp file left: {:?}", dir_entries(dir.path()));
    assert!(PngFile::create(&dir.path().join("empty.png"), 0, 4, PngKind::Rgb8).is_err());
}

#[test]
fn atomic_replace_with_writes_what_the_closure_writes_or_keeps_the_old_file() {
    let dir = tempdir();
    let path = dir.path().join("view.js");
    std::fs::write(&path, "old").unwrap();
    vista_image::atomic_replace_with(&path, |w| w.write_all(b"new contents")).unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new contents");
    let failed = vista_image::atomic_replace_with(&path, |w| {
        w.write_all(b"half")?;
        Err(std::io::Error::other("the writer failed"))
    });
    assert!(failed.unwrap_err().to_string().contains("view.js"));
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new contents", "the old file is kept");
    assert_eq!(dir_entries(dir.path()), ["view.js"], "no temp file left");
}

/// A golden's view decoded in 16 bits (`decode_png16_compact`, the
/// verdict's) reads as the very f32 values `decode_png16` gives, row by
/// row and whole, for 16-bit RGBA and 8-bit RGB, RGBA and grey PNGs: every
/// 8-bit level and a spread of 16-bit ones.
#[test]
fn a_compact_png_decode_reads_as_the_full_one_bit_for_bit() {
    use vista_image::{Texels, decode_png16, decode_png16_compact};
    let p = Path::new("golden.png");
    let levels16 = Image::from_fn(256, 3, |x, y| {
        let v = ((x * 257 + y * 97) % 65536) as f32 / 65535.0;
        [v, 1.0 - v, (v * 3.0).fract(), 0.25 + v / 2.0]
    });
    let levels8 = |x: u32, y: u32| ((x + 85 * y) % 256) as u8;
    let pngs: Vec<Vec<u8>> = vec![
        vista_image::encode_png16(p, &levels16).unwrap(),
        vista_image::encode_png16(p, &gradient(33, 17)).unwrap(),
        {
            let mut b = std::io::Cursor::new(Vec::new());
            image::RgbImage::from_fn(256, 3, |x, y| image::Rgb([levels8(x, y), 255 - levels8(x, y), 7]))
                .write_to(&mut b, image::ImageFormat::Png)
                .unwrap();
            b.into_inner()
        },
        {
            let mut b = std::io::Cursor::new(Vec::new());
            image::RgbaImage::from_fn(256, 2, |x, y| image::Rgba([levels8(x, y), 0, 255, levels8(255 - x, y)]))
                .write_to(&mut b, image::ImageFormat::Png)
                .unwrap();
            b.into_inner()
        },
        {
            let mut b = std::io::Cursor::new(Vec::new());
            image::GrayImage::from_fn(256, 1, |x, _| image::Luma([x as u8]))
                .write_to(&mut b, image::ImageFormat::Png)
                .unwrap();
            b.into_inner()
        },
    ];
    let bits = |img: &Image| img.data.iter().flat_map(|t| t.map(f32::to_bits)).collect::<Vec<u32>>();
    for (i, bytes) in pngs.iter().enumerate() {
        let full = decode_png16(p, bytes).unwrap();
        let compact = decode_png16_compact(p, bytes).unwrap();
        assert_eq!(bits(&compact.to_image()), bits(&full), "png {i}");
        assert_eq!(compact.size(), full.dimensions());
        let mut buf = Vec::new();
        for y in 0..full.height {
            let row: Vec<u32> = compact.row(y, &mut buf).iter().flat_map(|t| t.map(f32::to_bits)).collect();
            let w = full.width as usize;
            assert_eq!(row, bits(&Image::from_raw(full.width, 1, full.data[y as usize * w..][..w].to_vec()).unwrap()));
        }
        assert_eq!(compact.get(full.width - 1, full.height - 1), full.get(full.width - 1, full.height - 1));
    }
}
