//! `target/vista-report/index.html`, a review page: the summary first
//! (failures worst-first, counts, backend and adapter, the command that was
//! run, one bless command for every failure), then one section per case:
//! metrics against thresholds, provenance (the golden's manifest entry beside
//! this run, the WGSL files that changed), and a viewer (flip, slider, synced
//! zoom, a readout of both 16-bit values under the cursor, a heat map with a
//! stated scale). Works offline from a copied folder: every file is linked
//! by a relative path, and the viewer's pixel data comes in each case's
//! `view.js` (a script, because pages opened from `file://` may not read
//! image pixels or fetch files).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine;
use vista_image::metrics::format_psnr;
use vista_image::{Image, PngFile, PngKind};

use vista_golden::{BAD_PIXEL_LIMIT, GoldenError, Outcome, Verdict, bless_all_command};

use crate::{html_escape, page};

const SCRIPT: &str = include_str!("report.js");

/// The empty file that marks a case folder as written by vista.
pub const CASE_MARKER: &str = ".vista-case";

/// The folder of passing cases' thumbnails, `<id>.png` each (no case id
/// has a dot): a folder per passing case made and removed on every run
/// was most of a small case's report time.
pub const THUMBS_DIR: &str = "thumbs.d";

/// The empty file that marks [`THUMBS_DIR`] as vista's.
const THUMBS_MARKER: &str = ".vista-thumbs";

/// Clears the case folders an earlier run left in `dir`, so a filtered run's
/// report shows only its own cases. Only folders holding vista's marker are
/// removed: a `--report-dir` pointed anywhere else loses nothing. The
/// report folder itself is the run's: a symlink in its place (planted to
/// lead the report out of the project) is replaced by a real folder, never
/// written through.
pub fn clear_case_folders(dir: &Path) -> Result<(), GoldenError> {
    vista_image::own_dir(dir)?;
    let Ok(entries) = std::fs::read_dir(dir) else { return Ok(()) };
    for e in entries.flatten() {
        // Never through a symlink: a link to a marked folder elsewhere stays.
        let real = e.file_type().is_ok_and(|t| t.is_dir());
        if real && e.path().join(CASE_MARKER).is_file() {
            std::fs::remove_dir_all(e.path())
                .map_err(|err| GoldenError::Io { path: e.path().display().to_string(), message: err.to_string() })?;
        }
    }
    Ok(())
}

/// A checked case with its images written into `dir`: the outcome with
/// `files` filled in, its verdict as judged (never changed here), and what
/// could not be written (the run's failure, not the case's).
pub fn file_case(dir: &Path, checked: vista_golden::Checked, detail: Detail) -> (Outcome, Vec<String>) {
    let vista_golden::Checked {
        mut outcome, actual, expected, expected_png, output_images, pending_files, inputs, ..
    } = checked;
    // The golden's view, held in 16 bits through the verdict, as the
    // images below read it (the render's raw values are gone by now).
    let expected = expected.map(|e| e.to_image());
    let mut unwritten = Vec::new();
    if let Err(e) = write_inputs(dir, &mut outcome, &inputs) {
        unwritten.push(e.to_string());
    }
    // What bless --from-report accepts besides the main PNG.
    let kept = (|| -> Result<(), GoldenError> {
        for (name, bytes) in &pending_files {
            let path = vista_golden::pending::pending_file(dir, &outcome.id, name);
            case_folder(dir, &outcome.id)?;
            if let Some(parent) = path.parent() {
                vista_image::own_dir(parent)?;
            }
            vista_image::atomic_replace(&path, bytes)?;
        }
        Ok(())
    })();
    if let Err(e) = kept {
        unwritten.push(e.to_string());
    }
    if let Some(actual) = &actual
        && let Err(e) = write_case_files(dir, &mut outcome, actual, expected.as_ref(), expected_png.as_deref(), detail)
    {
        unwritten.push(e.to_string());
    }
    if let Err(e) = write_output_images(dir, &mut outcome, &output_images) {
        unwritten.push(e.to_string());
    }
    (outcome, unwritten)
}

/// `<dir>/<id>/`, created and marked as vista's (so a later run may clear
/// it and nothing else).
fn case_folder(dir: &Path, id: &str) -> Result<std::path::PathBuf, GoldenError> {
    let case_dir = dir.join(id);
    vista_image::own_dir(&case_dir)?;
    let marker = case_dir.join(CASE_MARKER);
    if !marker.is_file() {
        vista_image::atomic_replace(&marker, b"")?;
    }
    Ok(case_dir)
}

/// Writes a pass graph's other texture outputs (8-bit, the render's and
/// the golden's) into `<dir>/<id>/` for the outputs table.
fn write_output_images(
    dir: &Path,
    out: &mut Outcome,
    images: &[(String, Image, Option<Image>)],
) -> Result<(), GoldenError> {
    if images.is_empty() {
        return Ok(());
    }
    let id = out.id.clone();
    let case_dir = case_folder(dir, &id)?;
    for (name, actual, expected) in images {
        let write = |which: &str, img: &Image| -> Result<String, GoldenError> {
            let file = format!("{}.{which}8.png", name.replace('@', "-"));
            vista_image::write_png8(&case_dir.join(&file), img)?;
            Ok(format!("{id}/{file}"))
        };
        let e = expected.as_ref().map(|img| write("expected", img)).transpose()?;
        let a = Some(write("actual", actual)?);
        out.files.outputs.push((name.clone(), e, a));
    }
    Ok(())
}

/// Records a pass graph's inputs in `out.files.inputs`, writing each
/// texture's values as `<dir>/<id>/input.<name>8.png`.
fn write_inputs(dir: &Path, out: &mut Outcome, inputs: &[(String, String, Option<Image>)]) -> Result<(), GoldenError> {
    for (name, what, image) in inputs {
        let path = match image {
            Some(img) => {
                let file = format!("input.{name}8.png");
                vista_image::write_png8(&case_folder(dir, &out.id)?.join(&file), img)?;
                Some(format!("{}/{file}", out.id))
            }
            None => None,
        };
        out.files.inputs.push((name.clone(), what.clone(), path));
    }
    Ok(())
}

/// A thumbnail of an outputs or inputs table row, linked to its file;
/// nothing when there is no image.
fn linked_image(path: Option<&String>, alt: &str) -> String {
    match path {
        Some(p) => format!(
            "<a href=\"{0}\"><img class=\"thumb\" src=\"{0}\" alt=\"{1}\"></a>",
            html_escape(p),
            html_escape(alt)
        ),
        None => String::new(),
    }
}

/// A pass graph's inputs: each resource that starts from a file or inline
/// data, where from, and a texture's image.
fn inputs_table(o: &Outcome) -> String {
    if o.files.inputs.is_empty() {
        return String::new();
    }
    let mut t = String::from("<table class=\"outputs inputs\"><tr><th>input</th><th>from</th><th>image</th></tr>");
    for (name, what, path) in &o.files.inputs {
        let img = linked_image(path.as_ref(), name);
        t += &format!("<tr><td><b>{}</b></td><td>{}</td><td>{img}</td></tr>", html_escape(name), html_escape(what));
    }
    t + "</table>"
}

/// Where values were compared one by one: the worst of them and a
/// histogram of |difference| (bars scaled to the largest bin).
fn differences(v: &vista_golden::outputs::OutputVerdict) -> String {
    if v.histogram.iter().all(|(_, n)| *n == 0) {
        return String::new();
    }
    let most = v.histogram.iter().map(|(_, n)| *n).max().unwrap_or(1).max(1);
    let mut h = String::from("<table class=\"histogram\"><tr><th>|difference|</th><th>values</th><th></th></tr>");
    for (bin, n) in &v.histogram {
        let width = (120.0 * *n as f64 / most as f64).round() as u32;
        h += &format!(
            "<tr><td>{}</td><td>{n}</td><td><span class=\"bar\" style=\"width:{width}px\"></span></td></tr>",
            html_escape(bin)
        );
    }
    h += "</table>";
    if !v.worst.is_empty() {
        h += "<table class=\"worst\"><tr><th>where</th><th>this run</th><th>golden</th><th>|difference|</th></tr>";
        for (at, a, e) in &v.worst {
            h +=
                &format!("<tr><td>{}</td><td>{a}</td><td>{e}</td><td>{:.3e}</td></tr>", html_escape(at), (a - e).abs());
        }
        h += "</table>";
    }
    h
}

/// A pass graph's outputs: what each is, how it is judged, its result (or
/// problems) and, for textures other than the main image, both images.
fn outputs_table(o: &Outcome) -> String {
    // A lone main image judged by the case's thresholds on its PNG alone
    // (the seed's contract) says nothing the metrics table and the case's
    // problems do not.
    let plain = |v: &vista_golden::outputs::OutputVerdict| !v.by_tolerance && !v.by_raw && v.files.len() == 1;
    if o.outputs.is_empty() || (o.outputs.len() == 1 && plain(&o.outputs[0])) {
        return String::new();
    }
    let mut t = String::from(
        "<table class=\"outputs\"><tr><th>output</th><th>what</th><th>judged by</th><th>result</th><th>golden</th>\
         <th>this run</th></tr>",
    );
    for v in &o.outputs {
        let images = o.files.outputs.iter().find(|(n, _, _)| *n == v.name);
        let img = |p: Option<&String>| linked_image(p, &v.name);
        let mut result: Vec<String> =
            v.problems.iter().map(|p| format!("<div class=\"problem\">{}</div>", html_escape(p))).collect();
        result.extend(
            v.missing
                .iter()
                .map(|m| format!("<div class=\"problem\">missing {}</div>", html_escape(&m.display().to_string()))),
        );
        result.extend(v.errors.iter().map(|m| format!("<div class=\"problem\">{}</div>", html_escape(m))));
        if result.is_empty() {
            result.push(html_escape(&v.summary));
        }
        result.push(differences(v));
        t += &format!(
            "<tr><td><b>{}</b><br><small>{}</small></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            html_escape(&v.name),
            html_escape(&v.files.join(", ")),
            html_escape(&v.kind),
            html_escape(&v.judged_by),
            result.join(""),
            img(images.and_then(|i| i.1.as_ref())),
            img(images.and_then(|i| i.2.as_ref())),
        );
    }
    t + "</table>"
}

/// `to` as a link from a page in `from_dir`: relative where both lie on
/// one filesystem root (a report that moves with its checkout keeps its
/// links), with `/` separators.
pub fn href(from_dir: &Path, to: &Path) -> String {
    let (Ok(from), Ok(to)) = (std::path::absolute(from_dir), std::path::absolute(to)) else {
        return to.display().to_string();
    };
    let (from, to): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); from.len() - common];
    parts.extend(to[common..].iter().map(|c| c.as_os_str().to_string_lossy().to_string()));
    parts.join("/")
}

/// The longer side of a passing case's thumbnail, in texels (the index
/// shows it 32 pixels high).
pub const THUMB_EDGE: u32 = 128;

/// Writes one case's report images into `<dir>/<id>/` and records their
/// relative paths in `out.files`: the actual display values (16-bit and an
/// 8-bit copy), the golden's when there is one, and where both have the
/// same size the diff heat map (fixed log scale) and the viewer's data.
/// `expected_png`, where given, is the golden PNG that decodes to
/// `expected`: copied as `expected.png` rather than encoded again.
pub fn write_case_files(
    dir: &Path,
    out: &mut Outcome,
    actual: &Image,
    expected: Option<&Image>,
    expected_png: Option<&[u8]>,
    detail: Detail,
) -> Result<(), GoldenError> {
    let id = out.id.clone();
    // A case that passed gets one thumbnail of its render, linked to its
    // golden (which holds the full image): at 1920 x 1080 its 8-bit copies
    // and heat map were most of a passing case's cost. One that did not,
    // or a full report, gets every image at full size.
    let full = detail == Detail::All || !out.passed();
    if !full {
        let thumbs = dir.join(THUMBS_DIR);
        // A real folder of vista's: a symlink planted here is replaced, never written through.
        vista_image::own_dir(&thumbs)?;
        if !thumbs.join(THUMBS_MARKER).is_file() {
            vista_image::atomic_replace(&thumbs.join(THUMBS_MARKER), b"")?;
        }
        vista_image::write_png8_small(&thumbs.join(format!("{id}.png")), &actual.thumbnail(THUMB_EDGE))?;
        out.files.thumb = Some(format!("{THUMBS_DIR}/{id}.png"));
        return Ok(());
    }
    let case_dir = case_folder(dir, &id)?;
    let rel = |name: &str| Some(format!("{id}/{name}"));
    type Written = Result<(Option<String>, Option<String>), GoldenError>;
    // An image's 16-bit file (where `name16` is given) and its 8-bit display
    // copy, written together a row at a time from `row` (y, then the row to
    // fill): encoded whole, each held its samples and output at once (60-100
    // MB apiece at 2048 x 2048), and the heat map was one more f32 image.
    let pair = |name16: Option<&str>,
                name8: &str,
                (w, h): (u32, u32),
                opaque: bool,
                row: &mut dyn FnMut(usize, &mut Vec<[f32; 4]>)|
     -> Written {
        let mut full = name16.map(|n| PngFile::create(&case_dir.join(n), w, h, PngKind::Rgba16)).transpose()?;
        let kind = if opaque { PngKind::Rgb8 } else { PngKind::Rgba8 };
        let mut display = PngFile::create(&case_dir.join(name8), w, h, kind)?;
        let mut buf = Vec::with_capacity(w as usize);
        for y in 0..h as usize {
            buf.clear();
            row(y, &mut buf);
            if let Some(f) = &mut full {
                f.push_row(&buf)?;
            }
            display.push_row(&buf)?;
        }
        if let Some(f) = full {
            f.finish()?;
        }
        display.finish()?;
        Ok((name16.and_then(rel), rel(name8)))
    };
    // The viewer compares where both have one size; otherwise (a missing
    // golden, a size change) it shows the render alone, at full size.
    let comparable = expected.filter(|e| (e.width, e.height) == (actual.width, actual.height));
    let size = |img: &Image| (img.width, img.height);
    let renders =
        || pair(Some("actual.png"), "actual8.png", size(actual), vista_image::opaque8(actual), &mut rows_of(actual));
    let goldens = || -> Written {
        let Some(e) = expected else { return Ok((None, None)) };
        // The golden's own PNG where given, not encoded again.
        let name16 = match expected_png {
            Some(bytes) => {
                vista_image::atomic_replace(&case_dir.join("expected.png"), bytes)?;
                None
            }
            None => Some("expected.png"),
        };
        let (_, copy8) = pair(name16, "expected8.png", size(e), vista_image::opaque8(e), &mut rows_of(e))?;
        Ok((rel("expected.png"), copy8))
    };
    let heat_map = || -> Written {
        let Some(expected) = comparable else { return Ok((None, None)) };
        let w = actual.width as usize;
        pair(Some("diff.png"), "diff8.png", size(actual), true, &mut |y, buf| {
            vista_image::diff_heatmap_log_row(&expected.data[y * w..][..w], &actual.data[y * w..][..w], buf);
            outline_ignored(y as u32, buf, &out.ignore);
        })
    };
    // The viewer's data is both images' 16-bit values in base64: about
    // 1 MB per 256 x 256 case, more than half of a report. A reviewer
    // inspects pixels where a case did not pass.
    let first_bad = out.first_bad.as_ref().map(|b| (b.0, b.1));
    let viewer = || -> Result<Option<String>, GoldenError> {
        vista_image::atomic_replace_with(&case_dir.join("view.js"), |w| {
            write_view_js(w, &id, comparable, actual, first_bad)
        })?;
        Ok(rel("view.js"))
    };
    // A failing 1920 x 1080 case spent about 0.45 s here; cores the jobs
    // leave idle take half of it (measured at 1080p: the render's images
    // and the viewer's data 0.18 s, the golden's copies and the heat map's
    // 0.18 s).
    let (r, g, h, v) = if vista_image::threads_for(actual.data.len()) > 1 {
        std::thread::scope(|s| {
            let other = s.spawn(|| (goldens(), heat_map()));
            let (r, v) = (renders(), viewer());
            let (g, h) = other.join().expect("report images");
            (r, g, h, v)
        })
    } else {
        (renders(), goldens(), heat_map(), viewer())
    };
    (out.files.actual, out.files.actual8) = r?;
    if expected.is_some() {
        (out.files.expected, out.files.expected8) = g?;
    }
    if comparable.is_some() {
        (out.files.diff, out.files.diff8) = h?;
    }
    out.files.view = v?;
    Ok(())
}

/// Row `y` of `img` appended to a buffer, as `write_case_files` writes rows.
fn rows_of(img: &Image) -> impl FnMut(usize, &mut Vec<[f32; 4]>) + '_ {
    let w = img.width as usize;
    move |y, buf| buf.extend_from_slice(&img.data[y * w..][..w])
}

/// Outlines the ignored rectangles `[x, y, w, h]` in cyan on row `y` of a
/// heat map.
fn outline_ignored(y: u32, row: &mut [[f32; 4]], ignore: &[[u32; 4]]) {
    const CYAN: [f32; 4] = [0.0, 1.0, 1.0, 1.0];
    let width = row.len() as u32;
    for &[rx, ry, rw, rh] in ignore {
        if rw == 0 || rh == 0 || y < ry || y > ry + (rh - 1) {
            continue;
        }
        if y == ry || y == ry + (rh - 1) {
            for x in rx..(rx + rw).min(width) {
                row[x as usize] = CYAN;
            }
        } else {
            for x in [rx, rx + (rw - 1)] {
                if x < width {
                    row[x as usize] = CYAN;
                }
            }
        }
    }
}

/// Which cases get their 16-bit images and the pixel viewer's data
/// (`view.js`) in the report; the others get 8-bit images.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detail {
    /// Cases that did not pass (the default: a passing case's 16-bit copies
    /// and viewer data were two thirds of a report that nobody opens).
    #[default]
    Failing,
    /// Every case (`vista check --full-report`).
    All,
}

/// What a report says about the run that made it.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct RunSummary {
    /// The command line, as a user would type it again.
    pub command: String,
    /// lavapipe | swiftshader | browser | gpu.
    pub backend: String,
    /// The adapter's description (name | driver | backend | type).
    pub adapter: String,
    /// Cases whose render the report keeps for `vista bless --from-report`.
    pub pending: Vec<String>,
    /// The report folder as that command names it.
    pub accept_from: String,
    /// `--partition K/N`: the shard of a suite this run checked (what
    /// `vista merge` joins).
    #[serde(default)]
    pub partition: Option<(u64, u64)>,
    /// A coverage run's summary line (every case's hits summed), if the
    /// run measured coverage.
    pub coverage: Option<String>,
    /// Why the run stopped before its last case (an interrupt), if it did:
    /// the report then holds the cases that finished.
    #[serde(default)]
    pub stopped: Option<String>,
    /// The WGSL unit tests the run ran (`vista::harness`), in id order.
    #[serde(default)]
    pub unit_tests: Vec<UnitTest>,
}

/// A WGSL unit test's result as a report lists it.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct UnitTest {
    /// `wgsl::<file stem>::<fn>`.
    pub id: String,
    /// Empty when it passed: a line per failed assertion (`file:line:col:
    /// what`), or the error that kept it from running.
    pub failures: Vec<String>,
    /// Under coverage, one test of each file carries the file's coverage
    /// run (LCOV), or why it was not measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<Result<String, String>>,
}

impl UnitTest {
    /// Whether every assertion held.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

/// The index's section of WGSL unit tests: a count, then each failing
/// test with its failures, then the passing ones' ids.
fn unit_test_section(tests: &[UnitTest]) -> String {
    if tests.is_empty() {
        return String::new();
    }
    let failing: Vec<&UnitTest> = tests.iter().filter(|t| !t.passed()).collect();
    let mut out = format!(
        "<section id=\"unit-tests\"><h2>WGSL unit tests</h2><p class=\"counts\"><b>{}</b> tests: \
         <b class=\"{}\">{} failing</b>, {} passed.</p>",
        tests.len(),
        if failing.is_empty() { "ok" } else { "bad" },
        failing.len(),
        tests.len() - failing.len()
    );
    if !failing.is_empty() {
        out += "<table class=\"failures\"><tr><th>test</th><th>failed assertions</th></tr>";
        for t in &failing {
            let lines: Vec<String> = t.failures.iter().map(|f| html_escape(f)).collect();
            let _ = write!(out, "<tr><td class=\"id\">{}</td><td>{}</td></tr>", html_escape(&t.id), lines.join("<br>"));
        }
        out += "</table>";
    }
    let passing: Vec<String> = tests.iter().filter(|t| t.passed()).map(|t| html_escape(&t.id)).collect();
    if !passing.is_empty() {
        let _ = write!(out, "<p>Passed: <code>{}</code></p>", passing.join("</code>, <code>"));
    }
    out + "</section>\n"
}

/// The most texels a case's viewer data holds (2048 x 2048: about 67 MB
/// of view.js with both images).
pub const MAX_VIEW_TEXELS: usize = 2048 * 2048;

/// The viewer's data for one case: both images' 16-bit display values
/// (RGB, little-endian u16, base64; `expected` null when there is no
/// golden of the render's size) and the first bad pixel.
pub fn view_js(id: &str, expected: Option<&Image>, actual: &Image, first_bad: Option<(u32, u32)>) -> String {
    let mut out = Vec::new();
    write_view_js(&mut out, id, expected, actual, first_bad).expect("writing to memory");
    String::from_utf8(out).expect("view.js is ASCII and JSON")
}

/// [`view_js`] written to `out` a row at a time: whole, a 2048 x 2048
/// case's was one 64 MiB string and its 16-bit values once more. A row's
/// 6 bytes a texel are a multiple of 3, so its base64 needs no padding and
/// the rows' texts join into the whole image's.
///
/// At most [`MAX_VIEW_TEXELS`] go in: a taller image (a 3d texture's or an
/// array's stacked layers: 512^3 made a 1 GB view.js) gives the rows around
/// its first bad pixel (else its first rows), and says which (`y0`,
/// `full_h`); the 16-bit PNGs beside it keep every row.
pub fn write_view_js(
    out: &mut dyn std::io::Write,
    id: &str,
    expected: Option<&Image>,
    actual: &Image,
    first_bad: Option<(u32, u32)>,
) -> std::io::Result<()> {
    let w = actual.width as usize;
    let full_h = actual.height as usize;
    let rows = (MAX_VIEW_TEXELS / w.max(1)).clamp(1, full_h.max(1));
    let y0 = first_bad.map_or(0, |(_, y)| (y as usize).saturating_sub(rows / 2)).min(full_h.saturating_sub(rows));
    let window = |img: &Image| -> Image {
        let data = img.data.get(y0 * w..(y0 + rows) * w).unwrap_or(&img.data).to_vec();
        Image { width: img.width, height: (data.len() / w.max(1)) as u32, data }
    };
    let cropped = (rows < full_h).then(|| (expected.map(window), window(actual)));
    let (expected, actual) = match &cropped {
        Some((e, a)) => (e.as_ref(), a),
        None => (expected, actual),
    };
    let first_bad = first_bad.map(|(x, y)| (x, y - y0 as u32));
    let mut bytes = Vec::with_capacity(w * 6);
    let mut text = vec![0u8; w * 8];
    let mut u16s = |out: &mut dyn std::io::Write, img: &Image| -> std::io::Result<()> {
        out.write_all(b"\"")?;
        for row in img.data.chunks(img.width.max(1) as usize) {
            bytes.clear();
            bytes
                .extend(row.iter().flat_map(|p| p[..3].iter().flat_map(|&v| vista_image::quantize16(v).to_le_bytes())));
            text.resize(bytes.len().div_ceil(3) * 4, 0);
            let n = base64::engine::general_purpose::STANDARD.encode_slice(&bytes, &mut text).expect("sized for it");
            out.write_all(&text[..n])?;
        }
        out.write_all(b"\"")
    };
    let id = serde_json::to_string(id).expect("a string");
    write!(
        out,
        "vistaCase({{\"id\":{id},\"w\":{},\"h\":{},\"y0\":{y0},\"full_h\":{full_h},\"expected\":",
        actual.width, actual.height
    )?;
    match expected {
        Some(e) => u16s(out, e)?,
        None => out.write_all(b"null")?,
    }
    out.write_all(b",\"actual\":")?;
    u16s(out, actual)?;
    let first_bad = first_bad.map_or("null".to_string(), |(x, y)| format!("[{x},{y}]"));
    writeln!(out, ",\"first_bad\":{first_bad}}});")
}

fn verdict_word(o: &Outcome) -> &'static str {
    match o.verdict {
        Verdict::Pass => "pass",
        Verdict::ExpectedFail => "expected failure",
        Verdict::Fail => "FAIL",
        Verdict::Missing => "MISSING",
        Verdict::Error => "ERROR",
    }
}

/// Worst first: errors and missing goldens, then failures by PSNR.
fn severity(o: &Outcome) -> (u8, i64) {
    let rank = match o.verdict {
        Verdict::Error => 0,
        Verdict::Missing => 1,
        Verdict::Fail => 2,
        Verdict::ExpectedFail => 3,
        Verdict::Pass => 4,
    };
    let psnr =
        o.metrics.map(|m| if m.psnr.is_finite() { (m.psnr * 1000.0) as i64 } else { i64::MAX }).unwrap_or(i64::MIN);
    (rank, psnr)
}

pub(crate) fn anchor(id: &str) -> String {
    format!("case-{}", html_escape(id))
}

fn thumb(path: &Option<String>, full: &Option<String>, alt: &str) -> String {
    match (path, full) {
        (Some(p), Some(f)) => format!(
            "<a href=\"{f}\" title=\"16-bit file\"><img class=\"thumb\" src=\"{p}\" alt=\"{alt}\" loading=\"lazy\"></a>",
            f = html_escape(f),
            p = html_escape(p)
        ),
        // A passing case keeps its 8-bit image only.
        (Some(p), None) => format!(
            "<a href=\"{p}\" title=\"8-bit file\"><img class=\"thumb\" src=\"{p}\" alt=\"{alt}\" loading=\"lazy\"></a>",
            p = html_escape(p)
        ),
        _ => format!("<span class=\"none\">no {alt}</span>"),
    }
}

/// The golden's manifest entry beside this run, mismatches marked.
/// The golden's provenance beside this run's, as a table, and whether any
/// row but the date differs.
fn provenance(o: &Outcome) -> (String, bool) {
    let mut any_differs = false;
    let mut t = format!(
        "<table class=\"prov\"><tr><th></th><th>golden (manifest): <code>{}</code></th><th>this run</th></tr>",
        html_escape(&o.golden_file)
    );
    let golden = o.golden.as_ref();
    fn split(a: &str, i: usize) -> String {
        a.split(" | ").nth(i).unwrap_or("").to_string()
    }
    let g = |f: fn(&vista_golden::ManifestEntry) -> String| golden.map(f).unwrap_or_else(|| "no manifest entry".into());
    let rows: [(&str, String, String); 7] = [
        (
            "backend",
            g(|e| if e.backend.is_empty() { "not recorded".into() } else { e.backend.clone() }),
            o.run.backend.clone(),
        ),
        ("adapter", g(|e| split(&e.adapter, 0)), split(&o.run.adapter, 0)),
        ("driver", g(|e| split(&e.adapter, 1)), split(&o.run.adapter, 1)),
        (
            "API | device",
            g(|e| format!("{} | {}", split(&e.adapter, 2), split(&e.adapter, 3))),
            format!("{} | {}", split(&o.run.adapter, 2), split(&o.run.adapter, 3)),
        ),
        ("date", g(|e| e.date.clone()), vista_golden::now_utc()),
        ("params hash", g(|e| e.params_hash.clone()), o.run.params_hash.clone()),
        ("shader hash", g(|e| e.shader_hash.clone()), o.run.shader_hash.clone()),
    ];
    for (name, then, now) in rows {
        let differs = name != "date" && golden.is_some() && then != now && then != "not recorded";
        any_differs |= differs;
        let _ = write!(
            t,
            "<tr class=\"{}\"><th>{name}</th><td>{}</td><td>{}</td></tr>",
            if differs { "differs" } else { "" },
            html_escape(&then),
            html_escape(&now)
        );
    }
    t += "</table>";
    if !o.changed_files.is_empty() {
        let _ = write!(
            t,
            "<p class=\"problem\">WGSL changed since the bless: {}</p>",
            o.changed_files.iter().map(|f| format!("<code>{}</code>", html_escape(f))).collect::<Vec<_>>().join(", ")
        );
    }
    (t, any_differs)
}

fn metric_cells(o: &Outcome) -> (String, String) {
    match &o.metrics {
        Some(m) => {
            let psnr_bad = m.psnr < o.psnr_threshold;
            let ssim_bad = o.min_ssim.is_some_and(|t| m.ssim < t);
            let flip_bad = m.flip_mean.zip(o.max_flip).is_some_and(|(f, t)| f > t);
            let cls = |bad: bool| if bad { " class=\"bad\"" } else { "" };
            let table = format!(
                "<table class=\"metrics\"><tr><th>PSNR{}</th><td{}>{}</td><td>&ge; {:.1} dB ({} driver)</td></tr>\
                 <tr><th>SSIM</th><td{}>{:.5}</td><td>{}</td></tr>\
                 <tr><th>FLIP mean</th><td{}>{}</td><td>{}</td></tr>\
                 <tr><th>max abs</th><td>{:.3e}</td><td></td></tr>\
                 <tr><th>bad pixels</th><td>{} ({:.3}%)</td><td>a channel differs by &gt; {BAD_PIXEL_LIMIT}</td></tr>\
                 <tr><th>NaN/Inf</th><td{}>{}</td><td>none allowed</td></tr></table>",
                if o.psnr_of_raw() { " (raw values)" } else { "" },
                cls(psnr_bad),
                format_psnr(m.psnr),
                o.psnr_threshold,
                if o.same_driver { "same" } else { "other" },
                cls(ssim_bad),
                m.ssim,
                o.min_ssim.map(|t| format!("&ge; {t}")).unwrap_or_else(|| "no threshold".into()),
                cls(flip_bad),
                m.flip_mean.map(|f| format!("{f:.5}")).unwrap_or_else(|| "-".into()),
                o.max_flip.map(|t| format!("&le; {t}")).unwrap_or_else(|| "no threshold".into()),
                m.max_abs,
                m.bad_pixels,
                o.bad_percent().unwrap_or(0.0),
                cls(m.nan > 0),
                m.nan,
            );
            (format_psnr(m.psnr), table)
        }
        None => ("-".into(), "<p>no comparison</p>".into()),
    }
}

/// Whether a case gets the short body: it passed with its render's bits
/// equal to its golden's (a thumbnail, not --full-report) and has nothing
/// else to show. Its tables said the same six lines for every such case:
/// most of a long suite's index.html.
fn is_plainly_identical(o: &Outcome) -> bool {
    o.files.thumb.is_some()
        && o.metrics.as_ref().is_some_and(|m| m.psnr == f64::INFINITY && m.nan == 0)
        && o.problems.is_empty()
        && o.notes.is_empty()
        && outputs_table(o).is_empty()
        && inputs_table(o).is_empty()
        && o.changed_files.is_empty()
}

/// The short body: the verdict's grounds in one line, and of the golden's
/// provenance only what differs from this run. The command for the case's
/// viewer is added by report.js when the row opens (its `plain` class):
/// written into each row it was a sixth of a long suite's report.
/// What a case's coverage run reached, each file linked to its page; or
/// why it was not measured.
fn case_coverage(o: &Outcome) -> String {
    match &o.coverage {
        None => String::new(),
        Some(Err(why)) => format!("<p class=\"note\">coverage not measured: {}</p>", html_escape(why)),
        Some(Ok(lcov)) => {
            let counts = vista_coverage::Counts::from_lcov(lcov);
            let files: Vec<String> = counts
                .files()
                .iter()
                .map(|f| format!("<a href=\"{}\">{}</a>", html_escape(&crate::coverage_page(f)), html_escape(f)))
                .collect();
            format!(
                "<p class=\"coverage\">coverage of this case: {}: {}</p>",
                html_escape(&crate::coverage_line(&counts)),
                files.join(", ")
            )
        }
    }
}

fn identical_body(o: &Outcome) -> String {
    let (prov, differs) = provenance(o);
    format!(
        "<p>identical to its golden <code>{golden}</code> (threshold &ge; {t:.1} dB, {driver} driver){same}</p>{prov}",
        golden = html_escape(&o.golden_file),
        t = o.psnr_threshold,
        driver = if o.same_driver { "same" } else { "other" },
        same = if differs { "" } else { "; recorded with this run's backend, adapter, driver, params and shaders" },
        prov = if differs { prov } else { String::new() },
    )
}

fn case_section(o: &Outcome, run: &RunSummary) -> String {
    let (psnr, metrics) = metric_cells(o);
    let failing = !o.passed();
    let msgs: String = o
        .problems
        .iter()
        .map(|p| format!("<div class=\"problem\">{}</div>", html_escape(p)))
        .chain(o.notes.iter().map(|n| format!("<div class=\"note\">{}</div>", html_escape(n))))
        .collect();
    let first_bad = o
        .first_bad
        .as_ref()
        .map(|(x, y, what)| {
            format!(
                "<p class=\"problem\">first bad pixel, marked in the viewer: ({x}, {y}) = {}</p>",
                html_escape(what)
            )
        })
        .unwrap_or_default();
    let viewer = match &o.files.view {
        Some(v) => format!(
            "<div class=\"viewer\" data-case=\"{}\" data-src=\"{}\"><p class=\"loading\">viewer loads when opened</p></div>",
            html_escape(&o.id),
            html_escape(v)
        ),
        None if o.files.thumb.is_some() => format!(
            "<p class=\"note\">The pixel viewer and 16-bit images are written for cases that do not pass; for \
             this one: <code class=\"cmd\">vista check --case '{}' --full-report</code></p>",
            html_escape(&o.id)
        ),
        None => String::new(),
    };
    let plain = is_plainly_identical(o);
    let coverage = case_coverage(o);
    let body = match plain {
        true => identical_body(o),
        false => format!(
            "<div class=\"cols\"><div>{metrics}{outputs}{first_bad}{msgs}\
             <p>bless this case: <code class=\"cmd\">{bless}</code></p>{accept}</div><div>{prov}</div></div>{viewer}",
            outputs = outputs_table(o) + &inputs_table(o),
            bless = html_escape(&o.bless_command),
            accept = match run.pending.contains(&o.id) {
                true => format!(
                    "<p>or accept this very render (on any machine with this checkout): <code class=\"cmd\">vista bless \
                     --from-report {} --case '{}'</code></p>",
                    html_escape(&run.accept_from),
                    html_escape(&o.id)
                ),
                false => String::new(),
            },
            prov = provenance(o).0,
        ),
    };
    format!(
        "<details class=\"case {cls}\" id=\"{anchor}\"{open}>\
         <summary><span class=\"verdict\">{verdict}</span> <b class=\"id\">{id}</b> <span class=\"kernel\">{kernel}</span> \
         <span class=\"psnr\">PSNR {psnr}</span> <span class=\"ms\">{gpu:.1} ms</span> \
         <span class=\"thumbs\">{thumbs}</span></summary><div class=\"body\">{body}{coverage}</div></details>\n",
        cls = match (failing, plain) {
            (true, _) => "fail",
            (false, true) => "pass plain",
            (false, false) => "pass",
        },
        anchor = anchor(&o.id),
        open = if failing { " open" } else { "" },
        verdict = verdict_word(o),
        id = html_escape(&o.id),
        kernel = html_escape(&o.kernel),
        gpu = o.gpu_ms,
        thumbs = match (&o.files.actual8, o.outputs.is_empty()) {
            // A passing case: its render's thumbnail, linked to its golden.
            _ if o.files.thumb.is_some() => {
                let src = html_escape(o.files.thumb.as_deref().unwrap_or_default());
                let href = o.files.golden_href.as_deref().map_or(src.clone(), html_escape);
                format!(
                    "<a href=\"{href}\" title=\"the golden file\"><img class=\"thumb\" src=\"{src}\" alt=\"render\" \
                     loading=\"lazy\"></a>"
                )
            }
            // A graph whose first output is a buffer has no main image.
            (None, false) => format!(
                "<span class=\"none\">outputs: {}</span>",
                html_escape(&o.outputs.iter().map(|v| v.name.as_str()).collect::<Vec<_>>().join(", "))
            ),
            _ => format!(
                "{} {} {}",
                thumb(&o.files.expected8, &o.files.expected, "expected"),
                thumb(&o.files.actual8, &o.files.actual, "actual"),
                thumb(&o.files.diff8, &o.files.diff, "heat map")
            ),
        },
    )
}

/// Writes the report (atomically), removes the thumbnails none of
/// `outcomes` shows ([`prune_thumbs`]) and returns the index path.
pub fn write_report(dir: &Path, run: &RunSummary, outcomes: &[Outcome]) -> Result<PathBuf, GoldenError> {
    let index = write_index(dir, run, outcomes)?;
    prune_thumbs(dir, outcomes);
    Ok(index)
}

/// [`write_report`] without pruning: for a run whose other processes may be
/// filing cases (and their thumbnails) the index does not list yet.
pub fn write_index(dir: &Path, run: &RunSummary, outcomes: &[Outcome]) -> Result<PathBuf, GoldenError> {
    let mut sorted: Vec<&Outcome> = outcomes.iter().collect();
    sorted.sort_by_key(|o| (severity(o), o.id.clone()));
    let failing: Vec<&Outcome> = sorted.iter().copied().filter(|o| !o.passed()).collect();
    let xfail = sorted.iter().filter(|o| o.verdict == Verdict::ExpectedFail).count();
    let passed = sorted.len() - failing.len() - xfail;
    let mut summary = String::new();
    if failing.is_empty() {
        summary += "<p class=\"allpass\">Every case passed.</p>";
    } else {
        summary += "<table class=\"failures\"><tr><th>case</th><th>verdict</th><th>PSNR</th><th>threshold</th>\
                    <th>bad pixels</th><th>FLIP</th><th>changed WGSL</th><th>first problem</th></tr>";
        for o in &failing {
            let _ = write!(
                summary,
                "<tr><td class=\"id\"><a href=\"#{}\">{}</a></td><td>{}</td><td>{}</td><td>&ge; {:.1} dB</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                anchor(&o.id),
                html_escape(&o.id),
                verdict_word(o),
                o.metrics.map(|m| format_psnr(m.psnr)).unwrap_or_else(|| "-".into()),
                o.psnr_threshold,
                o.metrics
                    .map(|m| format!("{} ({:.3}%)", m.bad_pixels, o.bad_percent().unwrap_or(0.0)))
                    .unwrap_or_else(|| "-".into()),
                o.metrics.and_then(|m| m.flip_mean).map(|f| format!("{f:.5}")).unwrap_or_else(|| "-".into()),
                html_escape(&o.changed_files.join(", ")),
                html_escape(o.problems.first().map(String::as_str).unwrap_or("")),
            );
        }
        summary += "</table>";
        let ids: Vec<&str> = failing.iter().map(|o| o.id.as_str()).collect();
        if let Some(cmd) = bless_all_command(&ids) {
            let _ = write!(
                summary,
                "<p>If every change is intended, bless {} after review: <code class=\"cmd\">{}</code></p>",
                if ids.len() == 1 { "it".to_string() } else { format!("all {}", ids.len()) },
                html_escape(&cmd)
            );
        }
        if !run.pending.is_empty() {
            let _ = write!(
                summary,
                "<p>Or accept exactly what this run rendered ({} case{}), on any machine with this checkout: \
                 <code class=\"cmd\">vista bless --from-report {}</code></p>",
                run.pending.len(),
                if run.pending.len() == 1 { "" } else { "s" },
                html_escape(&run.accept_from)
            );
        }
    }
    let expectations: String = sorted
        .iter()
        .filter(|o| o.verdict == Verdict::ExpectedFail)
        .map(|o| {
            format!(
                "<li><a href=\"#{}\">{}</a>: {}</li>",
                anchor(&o.id),
                html_escape(&o.id),
                html_escape(&o.notes.join("; "))
            )
        })
        .collect();
    let expectations = if expectations.is_empty() {
        String::new()
    } else {
        format!("<p>Expected failures (golden/cases.toml):</p><ul>{expectations}</ul>")
    };
    // The other pages of the same folder, when a run wrote them.
    let others: String = [("matrix.html", "case x backend matrix"), ("mutants.html", "mutation score")]
        .iter()
        .filter(|(f, _)| dir.join(f).exists())
        .map(|(f, what)| format!(" <a href=\"{f}\">{what}</a>"))
        .collect();
    let stops = serde_json::to_string(&vista_image::HEATMAP_STOPS).expect("stops serialise");
    let sections: String = sorted.iter().map(|o| case_section(o, run)).collect();
    let body = format!(
        "<header><h1>vista report</h1>\
         <p class=\"counts\"><b>{n}</b> cases: <b class=\"{fcls}\">{nfail} failing</b>, {passed} passed, {xfail} expected failures.</p>\
         <p>Backend <b>{backend}</b>, adapter <code>{adapter}</code>. Command: <code class=\"cmd\">{command}</code>. Written {date}.{others}</p>{coverage}{stopped}\
         </header>\n<section id=\"summary\"><h2>Failures, worst first</h2>{summary}{expectations}</section>\n{units}\
         <section id=\"controls\"><label><input type=\"checkbox\" id=\"failures-only\"{checked}> failures only</label> \
         <label>heat map scale <select id=\"heat-scale\"><option value=\"log\">log, fixed: 1/65535 .. 1 (same in every case)</option>\
         <option value=\"max\">linear, 0 .. this case's max</option><option value=\"fixed\">linear, 0 .. the value on the right</option></select></label> \
         <label>white at <input id=\"heat-max\" type=\"number\" value=\"0.0039216\" step=\"any\" min=\"0\" \
         title=\"the difference drawn white on the fixed linear scale (0.0039216 = 1/255)\"> (fixed linear scale)</label> \
         <span class=\"help\">In a viewer: <kbd>f</kbd> flips expected/actual, the wheel or +/- zooms (all views together), drag pans.</span></section>\n\
         <section id=\"cases\"><h2>Cases</h2>\n{sections}</section>",
        n = sorted.len(),
        stopped =
            run.stopped.as_ref().map_or(String::new(), |s| format!("<p class=\"bad\"><b>{}</b></p>", html_escape(s))),
        coverage = run.coverage.as_ref().map_or(String::new(), |c| format!(
            "<p class=\"counts\">WGSL coverage: <a href=\"coverage/index.html\">{}</a></p>",
            html_escape(c)
        )),
        nfail = failing.len(),
        fcls = if failing.is_empty() { "ok" } else { "bad" },
        backend = html_escape(&run.backend),
        adapter = html_escape(&run.adapter),
        command = html_escape(&run.command),
        date = vista_golden::now_utc(),
        checked = if failing.is_empty() { "" } else { " checked" },
        units = unit_test_section(&run.unit_tests),
    );
    let script = format!("const HEAT_STOPS = {stops};\nconst LOG_FLOOR = {:e};\n{SCRIPT}", vista_image::LOG_FLOOR);
    let html = page(&format!("vista report: {} failing of {}", failing.len(), sorted.len()), &body, Some(&script));
    std::fs::create_dir_all(dir)
        .map_err(|e| GoldenError::Io { path: dir.display().to_string(), message: e.to_string() })?;
    let index = dir.join("index.html");
    vista_image::atomic_replace(&index, html.as_bytes())?;
    Ok(index)
}

/// Removes the thumbnails no case of `outcomes` shows (an earlier run's,
/// or a case that failed this time), where the folder is vista's.
pub fn prune_thumbs(dir: &Path, outcomes: &[Outcome]) {
    let thumbs = dir.join(THUMBS_DIR);
    let linked = std::fs::symlink_metadata(&thumbs).is_ok_and(|m| m.file_type().is_symlink());
    if linked || !thumbs.join(THUMBS_MARKER).is_file() {
        return;
    }
    let shown: std::collections::HashSet<&str> = outcomes.iter().filter_map(|o| o.files.thumb.as_deref()).collect();
    for e in std::fs::read_dir(&thumbs).into_iter().flatten().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.ends_with(".png") && !shown.contains(format!("{THUMBS_DIR}/{name}").as_str()) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod href_tests {
    use super::*;

    #[test]
    fn links_are_relative_to_the_report_folder() {
        let h = |a: &str, b: &str| href(Path::new(a), Path::new(b));
        assert_eq!(h("/p/target/vista-report", "/p/golden/fbm/a.png"), "../../golden/fbm/a.png");
        assert_eq!(h("/p/r", "/p/r/a/thumb.png"), "a/thumb.png");
        assert_eq!(h("/tmp/x", "/p/golden/fbm/a@swiftshader.png"), "../../p/golden/fbm/a@swiftshader.png");
    }
}

#[cfg(test)]
mod view_tests {
    use super::*;

    #[test]
    fn ignored_rectangles_are_outlined_row_by_row() {
        let (w, h) = (6u32, 5u32);
        let ignore = [[1, 1, 3, 3], [4, 0, 5, 2]];
        let cyan: Vec<(u32, u32)> = (0..h)
            .flat_map(|y| {
                let mut row = vec![[0.0f32; 4]; w as usize];
                outline_ignored(y, &mut row, &ignore);
                row.into_iter().enumerate().filter(|(_, p)| *p == [0.0, 1.0, 1.0, 1.0]).map(move |(x, _)| (x as u32, y))
            })
            .collect();
        // The first rectangle's border (its middle texel (2, 2) stays), the
        // second's two rows clipped at the right edge.
        let expected = [(4, 0), (5, 0), (1, 1), (2, 1), (3, 1), (4, 1), (5, 1), (1, 2), (3, 2), (1, 3), (2, 3), (3, 3)];
        assert_eq!(cyan, expected);
        let mut row = vec![[0.0f32; 4]; 6];
        outline_ignored(0, &mut row, &[[0, 0, 0, 3], [0, 0, 2, 0]]);
        assert!(row.iter().all(|p| *p == [0.0; 4]), "an empty rectangle outlines nothing");
    }

    #[test]
    fn view_js_holds_both_images_16_bit_values_as_json() {
        let img = |v: f32| Image { width: 2, height: 1, data: vec![[v, 0.5, 1.0, 1.0], [0.0, 0.25, v, 1.0]] };
        let (expected, actual) = (img(0.1), img(0.2));
        let js = view_js("a \"b\"", Some(&expected), &actual, Some((1, 0)));
        let json = js.strip_prefix("vistaCase(").and_then(|s| s.strip_suffix(");\n")).expect("vistaCase(...);");
        let v: serde_json::Value = serde_json::from_str(json).expect("JSON");
        let values = |key: &str| -> Vec<u16> {
            let bytes = base64::engine::general_purpose::STANDARD.decode(v[key].as_str().expect(key)).expect("base64");
            bytes.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]])).collect()
        };
        let q = |x: f32| vista_image::quantize16(x);
        assert_eq!(v["id"], "a \"b\"");
        assert_eq!((v["w"].as_u64(), v["h"].as_u64()), (Some(2), Some(1)));
        assert_eq!(values("expected"), [q(0.1), q(0.5), q(1.0), q(0.0), q(0.25), q(0.1)]);
        assert_eq!(values("actual"), [q(0.2), q(0.5), q(1.0), q(0.0), q(0.25), q(0.2)]);
        assert_eq!(v["first_bad"], serde_json::json!([1, 0]));
        let alone = view_js("x", None, &actual, None);
        let v: serde_json::Value = serde_json::from_str(&alone["vistaCase(".len()..alone.len() - 3]).expect("JSON");
        assert!(v["expected"].is_null() && v["first_bad"].is_null());
    }

    /// A stacked 3d output taller than the cap: the viewer gets the rows
    /// around its first bad pixel, never more than MAX_VIEW_TEXELS, and
    /// says which rows of how many.
    #[test]
    fn a_tall_image_s_viewer_holds_the_rows_around_its_first_bad_pixel() {
        let (w, h) = (512u32, 512 * 64);
        let row_value = |y: u32| (y % 1000) as f32 / 1000.0;
        let img = Image {
            width: w,
            height: h,
            data: (0..h).flat_map(|y| vec![[row_value(y), 0.0, 0.0, 1.0]; w as usize]).collect(),
        };
        let js = view_js("tall", Some(&img), &img, Some((7, 20000)));
        assert!(js.len() < MAX_VIEW_TEXELS * 6 * 2 * 4 / 3 + 1000, "{} bytes", js.len());
        let json = js.strip_prefix("vistaCase(").and_then(|s| s.strip_suffix(");\n")).expect("vistaCase(...);");
        let v: serde_json::Value = serde_json::from_str(json).expect("JSON");
        let rows = (MAX_VIEW_TEXELS / w as usize) as u64;
        let y0 = 20000 - rows / 2;
        assert_eq!((v["h"].as_u64(), v["y0"].as_u64(), v["full_h"].as_u64()), (Some(rows), Some(y0), Some(h as u64)));
        assert_eq!(v["first_bad"], serde_json::json!([7, rows / 2]), "relative to the window");
        let first = base64::engine::general_purpose::STANDARD.decode(&v["actual"].as_str().unwrap()[..8]).unwrap();
        assert_eq!(
            u16::from_le_bytes([first[0], first[1]]),
            vista_image::quantize16(row_value(y0 as u32)),
            "row y0 first"
        );
        // Without a bad pixel: the first rows; a short image: all of it.
        let head = |js: String| js[..120].to_string();
        assert!(head(view_js("t", None, &img, None)).contains(&format!("\"h\":{rows},\"y0\":0,")));
        let short = Image { width: 4, height: 3, data: vec![[0.0; 4]; 12] };
        assert!(head(view_js("s", None, &short, Some((1, 2)))).contains("\"h\":3,\"y0\":0,\"full_h\":3,"));
    }
}
