//! `VISTA_VALIDATION=1`: the Khronos validation layer under wgpu. wgpu-hal
//! reports the layer's messages through the `log` crate; this logger keeps
//! every warning or error that wgpu-hal's Vulkan messenger forwards, and
//! each dispatch fails if any arrived while it ran.

use std::sync::Mutex;

static MESSAGES: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// The target wgpu-hal's Vulkan debug messenger logs under.
pub const TARGET: &str = "wgpu_hal::vulkan::instance";

struct Collector;

impl log::Log for Collector {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn && m.target().starts_with("wgpu_hal::vulkan")
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let text = record.args().to_string();
            // The messenger formats the message type first: only the layer's
            // VALIDATION messages count, not general or performance notes.
            if text.contains("VALIDATION") {
                MESSAGES.lock().expect("validation messages").push(text.replace('\n', " "));
            }
        }
    }
    fn flush(&self) {}
}

/// Installs the collector (once per process). Fails if another logger is set.
pub fn install() -> Result<(), String> {
    static INSTALLED: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    INSTALLED
        .get_or_init(|| {
            log::set_logger(&Collector).map_err(|e| format!("cannot collect validation messages: {e}"))?;
            log::set_max_level(log::LevelFilter::Warn);
            Ok(())
        })
        .clone()
}

/// The messages collected since the last call.
pub fn take() -> Vec<String> {
    std::mem::take(&mut *MESSAGES.lock().expect("validation messages"))
}
