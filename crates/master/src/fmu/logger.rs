//! The `log` backend for FMU logger messages and the master's own messages.

/// A `log` backend that prints FMU messages (target = instance name) and the master's own
/// messages to stderr as `[level] instance: message`.
pub struct FmuLogger;

impl log::Log for FmuLogger {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::max_level()
    }
    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let from_fmu = record.module_path() == Some("logger");
            if from_fmu {
                eprintln!(
                    "[{}] FMU instance '{}': {}",
                    record.level(),
                    record.target(),
                    record.args()
                );
            } else if record.target().starts_with("master") {
                eprintln!("[{}] {}", record.level(), record.args());
            }
        }
    }
    fn flush(&self) {}
}

static LOGGER: FmuLogger = FmuLogger;

/// Installs [`FmuLogger`] (once per process; later calls only change the level).
pub fn install_logger(level: log::LevelFilter) {
    let _ = log::set_logger(&LOGGER);
    log::set_max_level(level);
}
