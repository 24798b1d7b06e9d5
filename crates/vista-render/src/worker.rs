//! GPU work in a worker process (SPEC 14 "Crashes", SPEC 16): a driver that
//! crashes (lavapipe segfaults in its queue thread on some kernels) or hangs
//! takes down the worker, not the run. The binary (and `vista::harness`'s
//! test binary) re-executes itself with `VISTA_WORKER=1`; that process owns
//! a device and runs the graphs the parent plans ([`Worker::run`]), one at
//! a time, reporting each pass before it is submitted. When it dies by a
//! signal the case it was running fails with [`RenderError::Crashed`]
//! (naming the signal and the pass), when it stops answering it is killed
//! ([`vista_gpu::GpuError::Timeout`]), and the next run starts a new one.
//!
//! The wire: each message is a little-endian u32 length and that much JSON,
//! then a little-endian u64 length and that many bytes (a run's outputs,
//! raw: texels as f32 RGBA, buffers as they are).

use std::borrow::Cow;
use std::io::{BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

use serde::{Deserialize, Serialize};
use vista_gpu::{Context, GpuConfig, GpuError, OutputData, Readback, RunStats};
use vista_image::Image;

use crate::RenderError;

/// The variable that makes the binary a worker.
pub const WORKER_VAR: &str = "VISTA_WORKER";

/// A fault a worker raises on purpose (tests of the crash path), set by
/// `VISTA_WORKER_FAULT=<segv|abort|hang>:<case>` through `vista::Config`
/// (a case id; for `vista sweep`, a point's setting such as `octaves=4`, or
/// `reference`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum Fault {
    /// `raise(SIGSEGV)`, as a driver's bad pointer would.
    Segv,
    /// `abort()` (SIGABRT), as a driver's failed assertion would.
    Abort,
    /// Never answers, as a hung driver would.
    Hang,
}

impl Fault {
    /// `segv:<case>` and the like, or the error naming what is allowed.
    pub fn parse(text: &str) -> Result<(Fault, String), String> {
        let (kind, case) = text.split_once(':').unwrap_or((text, ""));
        let fault = match kind {
            "segv" => Fault::Segv,
            "abort" => Fault::Abort,
            "hang" => Fault::Hang,
            other => return Err(format!("'{other}' is not a fault; expected segv|abort|hang:<case id>")),
        };
        if case.is_empty() {
            return Err(format!("'{text}' names no case; expected {kind}:<case id>"));
        }
        Ok((fault, case.to_string()))
    }
}

/// How the worker rebuilds the parent's shaders: the project root (none:
/// the built-ins alone) and the files a mutant or a unit test replaces.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShaderSource {
    /// The project root.
    pub root: Option<PathBuf>,
    /// Files replaced, each a path (as `Sources::with_file` takes it) and
    /// its text: a mutant, a unit test file's rewrite.
    pub edits: Vec<(String, String)>,
    /// Kernels composed with coverage counters (a coverage run).
    #[serde(default)]
    pub coverage: bool,
    /// Vertex code counted too (the device lets the vertex stage write storage).
    #[serde(default)]
    pub vertex_counted: bool,
}

#[derive(Serialize, Deserialize)]
struct WireConfig {
    adapter: vista_gpu::AdapterChoice,
    validate: bool,
    timeout: Duration,
    wgpu_backends: Option<String>,
    /// The parent's `vista_gpu::compose_limit`.
    compose_limit: Duration,
}

/// A request to the worker. The parent sends the graph borrowed (a noise
/// kernel's 256 KiB table per case is not copied); the worker reads it
/// owned.
#[derive(Serialize, Deserialize)]
enum ToWorker<'a> {
    Init(WireConfig),
    Run {
        source: Cow<'a, ShaderSource>,
        resources: Cow<'a, [vista_gpu::Resource]>,
        passes: Cow<'a, [vista_gpu::GraphPass]>,
        outputs: Cow<'a, [vista_gpu::OutputRef]>,
        /// Each pass's source hash in the parent's set: a worker whose set
        /// differs (a file saved since it read the project) reads it again.
        hashes: Vec<String>,
        time_passes: bool,
        fault: Option<Fault>,
    },
}

#[derive(Serialize, Deserialize)]
enum FromWorker {
    /// Its device is made: what the parent's context describes it by.
    Ready(Box<vista_gpu::DeviceFacts>),
    Failed(WireError),
    Pass(String),
    Done(Result<ReadbackHead, WireError>),
}

/// A readback without its bytes (they follow the message).
#[derive(Serialize, Deserialize)]
struct ReadbackHead {
    /// Per output: a texture's (width, height, unwritten), or a buffer's length.
    outputs: Vec<Result<(u32, u32, u64), usize>>,
    stats: RunStats,
    pass_times: Vec<Duration>,
    pass_gpu_times: Vec<Option<Duration>>,
    compile: Duration,
}

/// A [`GpuError`] as it crosses the pipe (`NoAdapter`'s hint is static:
/// it is the choice's again on the other side).
#[derive(Serialize, Deserialize)]
enum WireError {
    NoAdapter { wanted: String, seen: String, choice: vista_gpu::AdapterChoice },
    Shader(String),
    Validation { what: String, message: String },
    Timeout { what: String, seconds: f64 },
    Request(String),
    Unsupported { adapter: String, what: String, feature: String },
    Device { adapter: String, message: String },
}

impl From<GpuError> for WireError {
    fn from(e: GpuError) -> WireError {
        match e {
            GpuError::Shader(m) => WireError::Shader(m),
            GpuError::Validation { what, message } => WireError::Validation { what, message },
            GpuError::Timeout { what, seconds } => WireError::Timeout { what, seconds },
            GpuError::Request(m) => WireError::Request(m),
            GpuError::Unsupported { adapter, what, feature } => WireError::Unsupported { adapter, what, feature },
            GpuError::Device { adapter, message } => WireError::Device { adapter, message },
            // Only a worker's start meets it, where its choice is at hand.
            e @ GpuError::NoAdapter { .. } => WireError::Device { adapter: "worker".into(), message: e.to_string() },
        }
    }
}

impl From<WireError> for GpuError {
    fn from(e: WireError) -> GpuError {
        match e {
            WireError::Shader(m) => GpuError::Shader(m),
            WireError::Validation { what, message } => GpuError::Validation { what, message },
            WireError::Timeout { what, seconds } => GpuError::Timeout { what, seconds },
            WireError::Request(m) => GpuError::Request(m),
            WireError::Unsupported { adapter, what, feature } => GpuError::Unsupported { adapter, what, feature },
            WireError::Device { adapter, message } => GpuError::Device { adapter, message },
            WireError::NoAdapter { wanted, seen, choice } => GpuError::NoAdapter { wanted, seen, hint: choice.hint() },
        }
    }
}

/// One message: its JSON head, then `parts` one after another (a
/// readback's outputs, written from where they lie: a 2048 x 2048 image
/// gathered into one buffer first was 64 MiB more of the worker's peak),
/// or the byte lists the head refers to (a request's tables, uniforms,
/// inputs: [`vista_gpu::wire`]) where there are no parts. Two lengths frame
/// it, by hand rather than with postcard or ciborium: they serialize a byte
/// list inside the message, so the parts would be copied in on one side and
/// out on the other (see [`receive_answer`]: 128 MiB held twice).
fn send<T: Serialize>(w: &mut impl Write, msg: &T, parts: &[&[u8]]) -> std::io::Result<()> {
    let (head, attached) = vista_gpu::wire::attach(|| serde_json::to_vec(msg).expect("wire messages serialize"));
    let parts = match attached.is_empty() {
        true => parts,
        false => {
            assert!(parts.iter().all(|p| p.is_empty()), "a message with byte lists carries no other bytes");
            &[&attached[..]]
        }
    };
    w.write_all(&(head.len() as u32).to_le_bytes())?;
    w.write_all(&head)?;
    w.write_all(&(parts.iter().map(|p| p.len() as u64).sum::<u64>()).to_le_bytes())?;
    for p in parts {
        w.write_all(p)?;
    }
    w.flush()
}

/// A message's JSON head and the length of the bytes after it.
fn receive_head(r: &mut impl Read) -> std::io::Result<(Vec<u8>, usize)> {
    let mut n = [0u8; 4];
    r.read_exact(&mut n)?;
    let mut head = vec![0u8; u32::from_le_bytes(n) as usize];
    r.read_exact(&mut head)?;
    let mut m = [0u8; 8];
    r.read_exact(&mut m)?;
    Ok((head, u64::from_le_bytes(m) as usize))
}

fn receive<T: for<'de> Deserialize<'de>>(r: &mut impl Read) -> std::io::Result<(T, Vec<u8>)> {
    let (head, len) = receive_head(r)?;
    let mut bytes = vec![0u8; len];
    r.read_exact(&mut bytes)?;
    let (msg, bytes) = vista_gpu::wire::read_attached(bytes, || serde_json::from_slice(&head));
    let msg = msg.map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    Ok((msg, bytes))
}

/// A worker's answer's bytes (a readback's outputs, one after another),
/// read into 16-byte texels so that a lone texture output becomes its
/// image without a copy: read as bytes and then copied, a 2048 x 2048
/// readback was held twice at once (128 MiB).
struct Answer {
    texels: Vec<[f32; 4]>,
    len: usize,
}

impl Answer {
    fn bytes(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.texels)[..self.len]
    }
}

/// [`receive`] of a worker's answer (answers carry no byte lists in their
/// head, only the outputs after it).
fn receive_answer(r: &mut impl Read) -> std::io::Result<(FromWorker, Answer)> {
    let (head, len) = receive_head(r)?;
    let mut texels = vec![[0.0f32; 4]; len.div_ceil(16)];
    r.read_exact(&mut bytemuck::cast_slice_mut(&mut texels)[..len])?;
    let msg = serde_json::from_slice(&head).map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e))?;
    Ok((msg, Answer { texels, len }))
}

/// Serves as a worker (the edge calls it when [`WORKER_VAR`] is set, first
/// in `main`): reads requests on stdin until it closes; the exit code.
pub fn serve_and_exit_code() -> i32 {
    // Ctrl-C reaches the whole process group; what an interrupt means
    // (finish the report of what finished) is the parent's to decide, and a
    // worker killed mid-case would look like a driver crash.
    // SAFETY: set before any thread starts; SIG_IGN is a valid disposition.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_IGN);
    }
    match serve() {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("vista worker: {e}");
            3
        }
    }
}

fn serve() -> std::io::Result<()> {
    let mut input = BufReader::new(std::io::stdin().lock());
    let out = Arc::new(Mutex::new(std::io::stdout()));
    let (first, _) = receive::<ToWorker<'static>>(&mut input)?;
    let ToWorker::Init(c) = first else {
        return Err(std::io::Error::other("the first request must be Init"));
    };
    vista_gpu::set_compose_limit(c.compose_limit);
    let config = GpuConfig {
        adapter: c.adapter,
        validate: c.validate,
        timeout: c.timeout,
        wgpu_backends: c.wgpu_backends,
        ..Default::default()
    };
    let failed = |e: WireError| send(&mut *out.lock().expect("stdout"), &FromWorker::Failed(e), &[]);
    let ctx = match Context::new(&config) {
        Ok(ctx) => ctx,
        Err(GpuError::NoAdapter { wanted, seen, .. }) => {
            return failed(WireError::NoAdapter { wanted, seen, choice: config.adapter });
        }
        Err(e) => return failed(e.into()),
    };
    let facts = ctx.facts().expect("a worker's device is a wgpu one");
    send(&mut *out.lock().expect("stdout"), &FromWorker::Ready(Box::new(facts)), &[])?;
    // The last two sets: a coverage run alternates judged and counted renders.
    let mut sets: Vec<(ShaderSource, vista_gpu::ShaderSet)> = Vec::new();
    let mut sources: Option<(Option<PathBuf>, crate::Sources)> = None;
    loop {
        let request = match receive::<ToWorker<'static>>(&mut input) {
            Ok((r, _)) => r,
            // The parent closed the pipe: the run is over.
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
            Err(e) => return Err(e),
        };
        let ToWorker::Run { source, resources, passes, outputs, hashes, time_passes, fault } = request else {
            return Err(std::io::Error::other("Init twice"));
        };
        let same = |set: &vista_gpu::ShaderSet| {
            passes.iter().zip(&hashes).all(|(p, h)| set.source_hash(&p.shader).is_ok_and(|mine| mine == *h))
        };
        let kept = sets.iter().find(|(s, set)| *s == *source && same(set)).map(|(_, set)| set.clone());
        let shaders = match kept {
            Some(set) => set,
            None => {
                // From the project as read, else as it is now on disk.
                let mut built = shader_set(&source, &mut sources).map_err(|e| WireError::Shader(e.to_string()));
                if built.as_ref().is_ok_and(|set| !same(set)) {
                    sources = None;
                    built = shader_set(&source, &mut sources).map_err(|e| WireError::Shader(e.to_string()));
                }
                let built = built.and_then(|set| match same(&set) {
                    true => Ok(set),
                    false => Err(WireError::Request(
                        "the worker's shaders differ from the parent's (a file changed during the run?)".into(),
                    )),
                });
                match built {
                    Ok(set) => {
                        sets.retain(|(s, _)| s.coverage != source.coverage);
                        sets.push((source.clone().into_owned(), set.clone()));
                        set
                    }
                    Err(err) => {
                        send(&mut *out.lock().expect("stdout"), &FromWorker::Done(Err(err)), &[])?;
                        continue;
                    }
                }
            }
        };
        let reporter = out.clone();
        ctx.on_pass(Some(Arc::new(move |label: &str| {
            let _ = send(&mut *reporter.lock().expect("stdout"), &FromWorker::Pass(label.to_string()), &[]);
            match fault {
                Some(Fault::Segv) => {
                    // SAFETY: the default action (a handler a library
                    // installed could return), then the signal: what the
                    // fault asks for.
                    unsafe {
                        libc::signal(libc::SIGSEGV, libc::SIG_DFL);
                        libc::raise(libc::SIGSEGV);
                    }
                }
                Some(Fault::Abort) => std::process::abort(),
                Some(Fault::Hang) => loop {
                    std::thread::sleep(Duration::from_secs(3600));
                },
                None => {}
            }
        })));
        ctx.time_passes(time_passes);
        let before = ctx.compile_time();
        let graph = vista_gpu::Graph { shaders: &shaders, resources, passes, outputs };
        let result = ctx.run(&graph);
        let compile = ctx.compile_time().saturating_sub(before);
        // A composition past its limit still runs on a thread of its own;
        // only ending the process stops it (the parent starts a fresh
        // worker for the next case).
        let runaway = vista_gpu::runaway_compositions() > 0;
        let mut out = out.lock().expect("stdout");
        match result {
            Err(e) => send(&mut *out, &FromWorker::Done(Err(e.into())), &[])?,
            Ok(r) => {
                let mut parts = Vec::new();
                let mut heads = Vec::new();
                for o in &r.outputs {
                    match o {
                        OutputData::Texture { image, unwritten } => {
                            heads.push(Ok((image.width, image.height, *unwritten)));
                            parts.push(image.le_bytes());
                        }
                        OutputData::Buffer(b) => {
                            heads.push(Err(b.len()));
                            parts.push(std::borrow::Cow::Borrowed(&b[..]));
                        }
                    }
                }
                let parts: Vec<&[u8]> = parts.iter().map(|p| &p[..]).collect();
                let head = ReadbackHead {
                    outputs: heads,
                    stats: r.stats,
                    pass_times: r.pass_times,
                    pass_gpu_times: r.pass_gpu_times,
                    compile,
                };
                send(&mut *out, &FromWorker::Done(Ok(head)), &parts)?
            }
        }
        if runaway {
            return Ok(());
        }
    }
}

/// The worker's shader set for `source`, reading the project once.
fn shader_set(
    source: &ShaderSource,
    cache: &mut Option<(Option<PathBuf>, crate::Sources)>,
) -> Result<vista_gpu::ShaderSet, RenderError> {
    if cache.as_ref().is_none_or(|(root, _)| *root != source.root) {
        let project = match &source.root {
            Some(root) => vista_project::Project::at(root)?,
            None => vista_project::Project::builtin_only(),
        };
        *cache = Some((source.root.clone(), crate::Sources::of(&project)?));
    }
    let sources = &cache.as_ref().expect("just filled").1;
    let set = match source.edits.is_empty() {
        true => sources.shader_set(),
        false => sources.with_files("edited", &source.edits),
    };
    Ok(if source.coverage { set.covered(source.vertex_counted) } else { set })
}

enum Heard {
    Message(FromWorker, Answer),
    Gone,
}

struct Proc {
    /// Its stdin stays in the `Child`, so that [`Proc::finish`] can close it.
    child: Child,
    heard: Receiver<Heard>,
}

impl Proc {
    fn stdin(&mut self) -> &mut ChildStdin {
        self.child.stdin.as_mut().expect("piped until finish")
    }

    /// Closes the worker's pipe, which it takes as the end of the run, and
    /// waits up to `grace` for it to exit; dropping kills it after that.
    fn finish(mut self, grace: Duration) {
        drop(self.child.stdin.take());
        let start = std::time::Instant::now();
        while start.elapsed() < grace {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

/// Ends every idle worker of this process and waits for it (at most two
/// seconds each): commands call it before they return, so no worker
/// outlives its command, and a worker's peak memory counts as the
/// command's (`/usr/bin/time` counts only children waited for; the
/// workers' 2048 x 2048 peak went unseen).
pub fn stop_all() {
    let workers = std::mem::take(&mut *WORKERS.lock().expect("workers"));
    for w in workers {
        let procs = std::mem::take(&mut *w.idle.lock().expect("idle workers"));
        for p in procs {
            p.finish(Duration::from_secs(2));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The parent's side: worker processes started on first use, one per
/// thread rendering at once (`check --jobs`: each job its own, as each had
/// its own share of one device before), kept idle between runs, and
/// replaced after one died.
pub struct Worker {
    exe: PathBuf,
    config: GpuConfig,
    /// The case whose run raises this fault (tests).
    fault: Option<(Fault, String)>,
    idle: Mutex<Vec<Proc>>,
    compile: Mutex<Duration>,
    /// What the first worker to start said of its device.
    facts: OnceLock<vista_gpu::DeviceFacts>,
}

/// What started the worker mode: this binary, and a fault to inject.
struct Mode {
    exe: PathBuf,
    fault: Option<(Fault, String)>,
}

static MODE: OnceLock<Mode> = OnceLock::new();
static WORKERS: Mutex<Vec<Arc<Worker>>> = Mutex::new(Vec::new());

/// Runs GPU work of this process in workers started from `exe` (this
/// binary, which calls [`serve_if_asked`] first), raising `fault` on a
/// named case. Renderers made after this get a worker for wgpu backends.
pub fn enable(exe: PathBuf, fault: Option<(Fault, String)>) {
    let _ = MODE.set(Mode { exe, fault });
}

impl Worker {
    /// The worker for `config`, when worker mode is on and the backend runs
    /// in this process (the browser backend is Chromium, already a process
    /// of its own): one per configuration, for the process's life.
    pub fn for_config(config: &GpuConfig) -> Option<Arc<Worker>> {
        let mode = MODE.get()?;
        if config.adapter == vista_gpu::AdapterChoice::Browser {
            return None;
        }
        let mut all = WORKERS.lock().expect("workers");
        if let Some(w) = all.iter().find(|w| w.config == *config) {
            return Some(w.clone());
        }
        let w = Arc::new(Worker {
            exe: mode.exe.clone(),
            config: config.clone(),
            fault: mode.fault.clone(),
            idle: Mutex::new(Vec::new()),
            compile: Mutex::new(Duration::ZERO),
            facts: OnceLock::new(),
        });
        all.push(w.clone());
        Some(w)
    }

    /// Time the workers spent compiling pipelines so far.
    pub fn compile_time(&self) -> Duration {
        *self.compile.lock().expect("compile time")
    }

    /// The facts of the device the workers hold, from a worker started
    /// for them (kept for the first run) unless one has already said.
    pub fn describe(&self) -> Result<vista_gpu::DeviceFacts, GpuError> {
        if let Some(f) = self.facts.get() {
            return Ok(f.clone());
        }
        let proc = self.start()?;
        self.idle.lock().expect("workers").push(proc);
        Ok(self.facts.get().expect("set by a worker's start").clone())
    }

    fn start(&self) -> Result<Proc, GpuError> {
        let failed = |m: String| GpuError::Device { adapter: "vista worker".into(), message: m };
        let mut child = Command::new(&self.exe)
            .env(WORKER_VAR, "1")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| failed(format!("cannot start {}: {e}", self.exe.display())))?;
        let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
        let (tx, heard) = channel();
        std::thread::spawn(move || {
            loop {
                match receive_answer(&mut stdout) {
                    Ok((m, bytes)) => {
                        if tx.send(Heard::Message(m, bytes)).is_err() {
                            return;
                        }
                    }
                    Err(_) => {
                        let _ = tx.send(Heard::Gone);
                        return;
                    }
                }
            }
        });
        let c = &self.config;
        let init = ToWorker::Init(WireConfig {
            adapter: c.adapter.clone(),
            validate: c.validate,
            timeout: c.timeout,
            wgpu_backends: c.wgpu_backends.clone(),
            compose_limit: vista_gpu::compose_limit(),
        });
        let mut proc = Proc { child, heard };
        send(proc.stdin(), &init, &[]).map_err(|e| failed(format!("cannot talk to the worker: {e}")))?;
        // Device creation: the watchdog's time, and then some.
        match proc.heard.recv_timeout(c.timeout + Duration::from_secs(30)) {
            Ok(Heard::Message(FromWorker::Ready(facts), _)) => {
                let _ = self.facts.set(*facts);
                Ok(proc)
            }
            Ok(Heard::Message(FromWorker::Failed(e), _)) => Err(e.into()),
            _ => {
                let status = proc.child.try_wait().ok().flatten();
                Err(failed(format!("the worker did not start ({})", describe_exit(status))))
            }
        }
    }

    /// Runs `graph` in the worker; `kernel` and `case` name it in a crash.
    pub fn run(
        &self,
        ctx: &Context,
        graph: &vista_gpu::Graph<'_>,
        source: &ShaderSource,
        kernel: &str,
        case: Option<&str>,
    ) -> Result<Readback, RenderError> {
        let taken = self.idle.lock().expect("workers").pop();
        let mut proc = match taken {
            Some(p) => p,
            None => self.start()?,
        };
        let fault = self.fault.as_ref().filter(|(_, c)| Some(c.as_str()) == case).map(|(f, _)| f.clone());
        let hashes = graph.passes.iter().map(|p| graph.shaders.source_hash(&p.shader)).collect::<Result<_, _>>()?;
        let request = ToWorker::Run {
            source: Cow::Borrowed(source),
            resources: Cow::Borrowed(&graph.resources),
            passes: Cow::Borrowed(&graph.passes),
            outputs: Cow::Borrowed(&graph.outputs),
            hashes,
            time_passes: ctx.timing_passes(),
            fault,
        };
        if send(proc.stdin(), &request, &[]).is_err() {
            // It died between runs: start another and try once more.
            proc = self.start()?;
            send(proc.stdin(), &request, &[]).map_err(|e| {
                RenderError::Gpu(GpuError::Device { adapter: ctx.adapter_description(), message: e.to_string() })
            })?;
        }
        let mut pass = String::from("its setup");
        // The worker's own watchdog covers every GPU wait, and it reports
        // each pass; this one covers a driver stuck outside them.
        let patience = self.config.timeout + Duration::from_secs(10);
        loop {
            match proc.heard.recv_timeout(patience) {
                Ok(Heard::Message(FromWorker::Pass(label), _)) => pass = label,
                Ok(Heard::Message(FromWorker::Done(result), bytes)) => {
                    let result = result.map_err(GpuError::from);
                    // A device the watchdog gave up on still runs the hung
                    // work, and the next run would wait behind it: that
                    // worker is dropped (killed), the next run starts another.
                    if !matches!(result, Err(GpuError::Timeout { .. })) {
                        self.idle.lock().expect("workers").push(proc);
                    }
                    return match result {
                        Err(e) => Err(RenderError::Gpu(e)),
                        Ok(head) => {
                            *self.compile.lock().expect("compile time") += head.compile;
                            Ok(readback(head, bytes))
                        }
                    };
                }
                Ok(Heard::Message(_, _)) => {}
                Ok(Heard::Gone) | Err(RecvTimeoutError::Disconnected) => {
                    let status = proc.child.wait().ok();
                    return Err(RenderError::Crashed(Box::new(crate::error::Crash {
                        backend: ctx.backend().to_string(),
                        adapter: ctx.adapter_description(),
                        how: describe_exit(status),
                        pass,
                        kernel: kernel.to_string(),
                    })));
                }
                // Dropping `proc` kills the worker.
                Err(RecvTimeoutError::Timeout) => {
                    return Err(RenderError::Gpu(GpuError::Timeout { what: pass, seconds: patience.as_secs_f64() }));
                }
            }
        }
    }
}

/// The outputs a [`ReadbackHead`] describes, from the bytes after it: a
/// lone texture output takes the answer's texels as they are.
fn readback(head: ReadbackHead, answer: Answer) -> Readback {
    let outputs = match head.outputs[..] {
        [Ok((width, height, unwritten))]
            if cfg!(target_endian = "little") && answer.len == width as usize * height as usize * 16 =>
        {
            let image = Image::from_raw(width, height, answer.texels).expect("one texel per pixel");
            vec![OutputData::Texture { image, unwritten }]
        }
        _ => {
            let bytes = answer.bytes();
            let mut at = 0;
            head.outputs
                .iter()
                .map(|o| match *o {
                    Ok((width, height, unwritten)) => {
                        let n = width as usize * height as usize * 16;
                        let image = Image::from_le_bytes(width, height, &bytes[at..at + n]).expect("sized");
                        at += n;
                        OutputData::Texture { image, unwritten }
                    }
                    Err(len) => {
                        at += len;
                        OutputData::Buffer(bytes[at - len..at].to_vec())
                    }
                })
                .collect()
        }
    };
    Readback { outputs, stats: head.stats, pass_times: head.pass_times, pass_gpu_times: head.pass_gpu_times }
}

/// `signal 11, SIGSEGV`, `exit status 3` or the like.
fn describe_exit(status: Option<std::process::ExitStatus>) -> String {
    use std::os::unix::process::ExitStatusExt;
    let Some(status) = status else { return "no exit status".into() };
    match status.signal() {
        Some(s) => {
            let name = match s {
                libc::SIGSEGV => "SIGSEGV",
                libc::SIGABRT => "SIGABRT",
                libc::SIGBUS => "SIGBUS",
                libc::SIGILL => "SIGILL",
                libc::SIGFPE => "SIGFPE",
                libc::SIGKILL => "SIGKILL",
                _ => "a signal",
            };
            format!("signal {s}, {name}")
        }
        None => format!("exit status {}", status.code().unwrap_or(-1)),
    }
}
