//! The FMU logger callback and the `log` backend for FMU messages and the master's own.
//!
//! FMI 2.0 (2.1.5) hands the logger a printf format plus variadic arguments, which only C can
//! expand: `csrc/fmi2_logger.c` does it defensively (NULL strings tolerated, a format with a
//! `%n` conversion passed on unexpanded instead of letting vsnprintf write through an
//! argument, text capped at 64 KiB) and calls [`master_fmi2_log`], which turns the text into a
//! `log` record. Nothing here can unwind into the FMU: an unknown status is logged as an
//! error, invalid UTF-8 is replaced, a failed write to stderr is ignored.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::io::Write;

use fmi_sys::fmi2 as ffi;

/// `module_path` of records that come from an FMU (their target is the instance name).
const FMU_RECORD: &str = "fmu";

/// A `log` backend that prints FMU messages (target = instance name) and the master's own
/// messages to stderr as `[level] instance: message`.
pub struct FmuLogger;

impl log::Log for FmuLogger {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::max_level()
    }
    fn log(&self, record: &log::Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let text = if record.module_path() == Some(FMU_RECORD) {
            // in a run set, the run the instance belongs to (runs in parallel interleave)
            match current_run() {
                Some(run) => format!(
                    "run '{run}', FMU instance '{}': {}",
                    record.target(),
                    record.args()
                ),
                None => format!("FMU instance '{}': {}", record.target(), record.args()),
            }
        } else if record.target().starts_with("master") {
            record.args().to_string()
        } else {
            return;
        };
        if CAPTURING.load(std::sync::atomic::Ordering::Relaxed) {
            keep_message(record.level(), text);
            return;
        }
        // eprintln! panics when stderr is closed; a lost log line must not stop a run
        let _ = writeln!(std::io::stderr().lock(), "[{}] {text}", record.level());
    }
    fn flush(&self) {}
}

static LOGGER: FmuLogger = FmuLogger;

/// Whether messages are kept for [`take_messages`] instead of printed (a host with its own
/// logging, e.g. Python's, where stderr is not what its user reads).
static CAPTURING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Messages kept at most between two takes: the newest (the ones that explain a failure);
/// older ones are counted, not kept.
const KEPT_MESSAGES: usize = 10_000;

/// The messages kept while capturing, oldest first, and how many older ones were dropped
/// beyond [`KEPT_MESSAGES`].
type Kept = (std::collections::VecDeque<(log::Level, String)>, usize);
static MESSAGES: std::sync::Mutex<Kept> =
    std::sync::Mutex::new((std::collections::VecDeque::new(), 0));

fn keep_message(level: log::Level, text: String) {
    // a poisoned lock (a panic while holding it) still holds a usable list
    let mut m = MESSAGES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if m.0.len() >= KEPT_MESSAGES {
        m.0.pop_front();
        m.1 += 1;
    }
    m.0.push_back((level, text));
}

/// Keeps the messages for [`take_messages`] (true) or prints them to stderr (false, the
/// default).
pub fn capture_messages(on: bool) {
    CAPTURING.store(on, std::sync::atomic::Ordering::Relaxed);
}

/// The messages kept since the last take (level, text), oldest first, and how many older ones
/// were dropped.
pub fn take_messages() -> (Vec<(log::Level, String)>, usize) {
    let mut m = MESSAGES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    (std::mem::take(&mut m.0).into(), std::mem::take(&mut m.1))
}

/// How many failure messages are kept per thread (the latest).
const KEPT_FAILURES: usize = 4;
/// Longest failure message kept [bytes].
const KEPT_FAILURE_BYTES: usize = 2048;

std::thread_local! {
    /// The run of a run set this thread computes, named in its FMUs' messages.
    static RUN: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Runs `f` with the FMU messages logged on this thread naming run `name` (the run set's
/// runs compute on worker threads, one run at a time each).
pub fn in_run<R>(name: &str, f: impl FnOnce() -> R) -> R {
    let before = RUN
        .try_with(|r| {
            r.try_borrow_mut()
                .ok()
                .map(|mut r| r.replace(name.to_string()))
        })
        .ok()
        .flatten()
        .flatten();
    let out = f();
    let _ = RUN.try_with(|r| {
        if let Ok(mut r) = r.try_borrow_mut() {
            *r = before;
        }
    });
    out
}

/// The run [`in_run`] names on this thread.
fn current_run() -> Option<String> {
    RUN.try_with(|r| r.try_borrow().ok().and_then(|r| r.clone()))
        .ok()
        .flatten()
}

std::thread_local! {
    /// Messages logged with fmi2Discard, fmi2Error or fmi2Fatal on this thread, as (instance,
    /// text), oldest first: an FMU logs within the call that fails, on the caller's thread,
    /// so the failed call's error can carry them ([`take_errors`]).
    static FAILURES: std::cell::RefCell<Vec<(String, String)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// The failure messages `instance` logged on this thread since the last take, joined; they
/// are removed. None when it logged none.
pub(crate) fn take_errors(instance: &str) -> Option<Box<str>> {
    FAILURES
        .try_with(|f| {
            let mut f = f.try_borrow_mut().ok()?;
            let (mine, others): (Vec<_>, Vec<_>) = f.drain(..).partition(|(i, _)| i == instance);
            *f = others;
            let texts: Vec<String> = mine.into_iter().map(|(_, m)| m).collect();
            (!texts.is_empty()).then(|| texts.join("; ").into_boxed_str())
        })
        .ok()
        .flatten()
}

fn keep_failure(instance: &str, text: &str) {
    let mut text = text.to_string();
    if text.len() > KEPT_FAILURE_BYTES {
        let mut cut = KEPT_FAILURE_BYTES;
        while !text.is_char_boundary(cut) {
            cut -= 1;
        }
        text.truncate(cut);
        text.push_str("...");
    }
    let _ = FAILURES.try_with(|f| {
        if let Ok(mut f) = f.try_borrow_mut() {
            if f.len() >= KEPT_FAILURES {
                f.remove(0);
            }
            f.push((instance.to_string(), text));
        }
    });
}

/// Installs [`FmuLogger`] (once per process; later calls only change the level).
pub fn install_logger(level: log::LevelFilter) {
    let _ = log::set_logger(&LOGGER);
    log::set_max_level(level);
}

/// Log level of an fmi2Status (an FMU may pass anything: unknown values are errors).
fn level(status: ffi::fmi2Status) -> log::Level {
    match status {
        ffi::fmi2Status_fmi2OK | ffi::fmi2Status_fmi2Pending => log::Level::Info,
        ffi::fmi2Status_fmi2Warning | ffi::fmi2Status_fmi2Discard => log::Level::Warn,
        _ => log::Level::Error,
    }
}

/// A C string from the FMU, or `fallback` for NULL; invalid UTF-8 is replaced.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string.
unsafe fn text(p: *const c_char, fallback: &str) -> String {
    if p.is_null() {
        fallback.to_string()
    } else {
        // SAFETY: non-null and NUL-terminated per the caller.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// Called by the C logger with the expanded (or, when `expanded` is 0, the raw) message of
/// `length` bytes.
///
/// # Safety
/// `instance` and `category` are NULL or NUL-terminated; `message` points to `length` bytes.
#[no_mangle]
pub unsafe extern "C" fn master_fmi2_log(
    _environment: *mut c_void,
    instance: *const c_char,
    status: ffi::fmi2Status,
    category: *const c_char,
    message: *const c_char,
    length: usize,
    expanded: c_int,
) {
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: per this function's contract.
        let (instance, category) = unsafe { (text(instance, "?"), text(category, "")) };
        let bytes = if message.is_null() || length == 0 {
            &[][..]
        } else {
            // SAFETY: the C side passes `length` readable bytes.
            unsafe { std::slice::from_raw_parts(message.cast::<u8>(), length) }
        };
        let body = String::from_utf8_lossy(bytes);
        let note = if expanded == 0 && !bytes.is_empty() {
            " (format not expanded: it contains %n)"
        } else {
            ""
        };
        let category = if category.is_empty() {
            String::new()
        } else {
            format!("[{category}] ")
        };
        if !matches!(
            status,
            ffi::fmi2Status_fmi2OK | ffi::fmi2Status_fmi2Warning | ffi::fmi2Status_fmi2Pending
        ) {
            keep_failure(&instance, &format!("{body}{note}"));
        }
        log::logger().log(
            &log::Record::builder()
                .args(format_args!("{category}{body}{note}"))
                .level(level(status))
                .module_path(Some(FMU_RECORD))
                .target(&instance)
                .build(),
        );
    });
}

extern "C" {
    /// The fmi2CallbackLogger (csrc/fmi2_logger.c); its C status parameter is an int, the
    /// same ABI as fmi2Status.
    fn master_fmi2_logger(
        environment: ffi::fmi2ComponentEnvironment,
        instance: ffi::fmi2String,
        status: ffi::fmi2Status,
        category: ffi::fmi2String,
        message: ffi::fmi2String,
        ...
    );
}

/// The logger callback handed to fmi2Instantiate.
pub(crate) fn callback() -> ffi::fmi2CallbackLogger {
    Some(master_fmi2_logger)
}
