//! `vista sweep`: argument checking, a progress bar, and the printed table
//! around `vista_sweep`.

use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use vista_golden::GoldenError;
use vista_project::Project;
use vista_render::Renderer;
use vista_sweep::{Axis, Metric, SweepSpec};

use crate::input::{bad, parse_sets};

#[derive(clap::Args)]
pub struct Args {
    pub kernel: String,
    #[arg(long)]
    pub preset: Option<String>,
    /// Fixed override NAME=VALUE for every point and the reference (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Numeric parameter to sweep.
    #[arg(long)]
    pub param: String,
    /// Comma-separated values of --param, e.g. 8,16,32,64.
    #[arg(long)]
    pub values: String,
    /// Second parameter for a 2-D grid (heat map).
    #[arg(long, requires = "values2")]
    pub param2: Option<String>,
    #[arg(long, requires = "param2")]
    pub values2: Option<String>,
    /// Reference override NAME=VALUE (repeatable); default: the kernel's high-quality settings.
    #[arg(long = "reference-set", value_name = "NAME=VALUE")]
    pub reference_set: Vec<String>,
    #[arg(long, default_value_t = vista_sweep::DEFAULT_TARGET_PSNR, allow_negative_numbers = true)]
    pub target_psnr: f64,
    #[arg(long, default_value = "128x128")]
    pub size: String,
    /// Timed renders per point (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub runs: u32,
    /// Compare display values (PSNR peak 1) or linear raw output (PSNR peak = reference max).
    #[arg(long, default_value = "display", value_name = "display|linear")]
    pub metric: String,
    #[arg(long)]
    pub out: PathBuf,
}

pub fn sweep(project: &Project, config: &vista::Config, a: Args) -> Result<i32, GoldenError> {
    let kernel = crate::input::registry(project)?.find(&a.kernel).cloned().map_err(bad)?;
    let (width, height) = vista_kernels::parse_size(&a.size).map_err(bad)?;
    let y = match (a.param2, a.values2) {
        (Some(name), Some(v)) => Some(Axis { name, values: vista_sweep::parse_values("--values2", &v)? }),
        _ => None,
    };
    let reference = if a.reference_set.is_empty() {
        kernel.high_quality().iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    } else {
        parse_sets(&a.reference_set)?
    };
    let spec = SweepSpec {
        kernel,
        preset: a.preset,
        base: parse_sets(&a.set)?,
        x: Axis { name: a.param, values: vista_sweep::parse_values("--values", &a.values)? },
        y,
        reference,
        width,
        height,
        target_psnr: a.target_psnr,
        runs: a.runs,
        metric: Metric::parse(&a.metric)?,
    };
    // Every value is checked before the device is touched.
    spec.resolve(&config.limits)?;
    crate::render::check_output_dir(&a.out)?;
    let ctx = &Renderer::shared(&config.gpu, project, config.limits)?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
            .expect("static template")
            .progress_chars("=> "),
    );
    let result = vista_sweep::run(ctx, &spec, |done, total, label| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(label.to_string());
    });
    bar.finish_and_clear();
    let sweep = result?;
    print!("{}", sweep.table());
    let (written, plot_problem) = sweep.write(&a.out, config.font.as_deref())?;
    for p in &written {
        println!("wrote {}", p.display());
    }
    if let Some(why) = plot_problem {
        eprintln!("warning: curve.svg and curve.png NOT written: {why}");
    }
    // The table named each crashed point; the points measured are written.
    Ok(if sweep.crashed.is_empty() { 0 } else { 1 })
}
