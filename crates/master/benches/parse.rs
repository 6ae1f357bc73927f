//! Reading a large modelDescription.xml: parse alone and `master inspect`'s whole check of an
//! FMU archive (zip, limits, parse, FMI 2.0 rules), for 10 000 and 100 000 variables. Both
//! must grow linearly with the number of variables.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // bench code

use std::io::Write;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

/// A description with `n` variables: a third parameters, a third outputs (all listed in
/// ModelStructure with dependencies), a third inputs.
fn description(n: usize) -> String {
    let mut s = String::with_capacity(n * 200);
    s.push_str(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Big" guid="{big}" variableNamingConvention="structured">
  <CoSimulation modelIdentifier="Big"/>
  <ModelVariables>
"#,
    );
    for i in 0..n {
        let (causality, extra) = match i % 3 {
            0 => ("parameter", r#" variability="fixed""#),
            1 => ("output", ""),
            _ => ("input", ""),
        };
        let start = if i % 3 == 1 { "" } else { r#" start="1""# };
        s.push_str(&format!(
            "    <ScalarVariable name=\"block[{i}].x\" valueReference=\"{i}\" causality=\"{causality}\"{extra} description=\"variable {i} &amp; more\"><Real unit=\"m\"{start}/></ScalarVariable>\n"
        ));
    }
    s.push_str("  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    for i in (1..n).step_by(3) {
        s.push_str(&format!(
            "      <Unknown index=\"{}\" dependencies=\"{}\"/>\n",
            i + 1,
            i + 2
        ));
    }
    s.push_str("    </Outputs>\n  </ModelStructure>\n</fmiModelDescription>\n");
    s
}

fn parse(c: &mut Criterion) {
    let mut g = c.benchmark_group("modelDescription");
    g.sample_size(10);
    for n in [10_000, 100_000] {
        let xml = description(n);
        g.bench_with_input(BenchmarkId::new("parse", n), &xml, |b, xml| {
            b.iter(|| master::model_description::ModelDescription::parse(xml).unwrap())
        });
        let dir = tempfile::tempdir().unwrap();
        let fmu = dir.path().join("Big.fmu");
        let mut z = zip::ZipWriter::new(std::fs::File::create(&fmu).unwrap());
        let o = zip::write::SimpleFileOptions::default();
        z.start_file("modelDescription.xml", o).unwrap();
        z.write_all(xml.as_bytes()).unwrap();
        let (platform, suffix) = master::fmu::platform_binary_dir().unwrap();
        z.start_file(format!("binaries/{platform}/Big{suffix}"), o)
            .unwrap();
        z.finish().unwrap();
        g.bench_with_input(BenchmarkId::new("open FMU", n), &fmu, |b, fmu| {
            b.iter(|| master::fmu::FmuArchive::open(fmu).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, parse);
criterion_main!(benches);
