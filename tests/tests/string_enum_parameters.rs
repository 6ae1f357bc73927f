//! String and Enumeration parameters of our FMUs set from a system description: Bogie2Dof's
//! contact table (`contact.table`, a String) and force law (`contact.model`, an Enumeration
//! given by item name or by its integer) reach the FMU. dist/ is built by scripts/test.sh.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)] // test code

use std::path::{Path, PathBuf};

use master::coupling::{RunOptions, SimOutput};
use master::system::LoadedSystem;

fn bogie_fmu() -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../dist/Bogie2Dof.fmu");
    assert!(
        p.exists(),
        "{} is missing: scripts/test.sh packages the FMUs into dist/ first",
        p.display()
    );
    std::path::absolute(p).unwrap()
}

fn run(parameters: &str) -> Result<SimOutput, String> {
    let text = format!(
        r#"{{"instances": [{{"name": "bogie", "fmu": "{}", "parameters": {{{parameters}}}}}],
            "stop_time": 0.5, "step": 0.001,
            "record": ["bogie.wheelset_front.lateral_displacement"]}}"#,
        bogie_fmu().display()
    );
    let sys = LoadedSystem::from_json_str(&text, Path::new("."), "bogie.json").unwrap();
    sys.run(&RunOptions::default()).map_err(|e| {
        let mut s = e.to_string();
        let mut src = std::error::Error::source(&e);
        while let Some(c) = src {
            s.push_str(&format!(": {c}"));
            src = c.source();
        }
        s
    })
}

fn last_y(out: &SimOutput) -> f64 {
    *out.column("bogie.wheelset_front.lateral_displacement")
        .unwrap()
        .last()
        .unwrap()
}

#[test]
fn contact_table_and_force_law_are_set_from_a_system_description() {
    let worn = run(r#""contact.model": "nonlinear", "contact.table": "worn""#).unwrap();
    let aa = run(r#""contact.model": "nonlinear", "contact.table": "AA""#).unwrap();
    let by_integer = run(r#""contact.model": 1, "contact.table": "AA""#).unwrap();
    let linear = run(r#""contact.model": "linear", "contact.table": "AA""#).unwrap();
    // another table gives another motion; the item name and its integer the same one
    let (yw, ya) = (last_y(&worn), last_y(&aa));
    assert!(
        (yw - ya).abs() > 1e-3 * yw.abs().max(ya.abs()),
        "worn {yw} vs AA {ya}"
    );
    assert_eq!(aa.data, by_integer.data);
    assert_ne!(aa.data, linear.data);
    // the FMU reads the table it is given: a missing file is refused when it initialises
    // (its message, naming the file, goes to the logger)
    let e =
        run(r#""contact.model": "nonlinear", "contact.table": "no_such_table.csv""#).unwrap_err();
    assert!(
        e.contains("fmi2ExitInitializationMode failed with fmi2Error"),
        "{e}"
    );
    // an unknown item is refused before any FMU call, with the items
    let e = run(r#""contact.model": "quadratic""#).unwrap_err();
    assert!(
        e.contains("'quadratic' is no item") && e.contains("'nonlinear' (1)"),
        "{e}"
    );
}
