//! Compiles the FMU logger callback (C: it expands the FMU's printf-style varargs).

fn main() {
    println!("cargo:rerun-if-changed=csrc/fmi2_logger.c");
    cc::Build::new()
        .file("csrc/fmi2_logger.c")
        .warnings(true)
        .compile("master_fmi2_logger");
}
