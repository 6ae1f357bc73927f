// A C logger for the test host: FMI 2.0's fmi2CallbackLogger is variadic, which stable Rust
// cannot define, so the test host's logger is written in C and forwards the formatted message.
fn main() {
    println!("cargo:rerun-if-changed=c/test_logger.c");
    cc::Build::new()
        .file("c/test_logger.c")
        .compile("test_logger");
}
