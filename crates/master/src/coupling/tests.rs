//! Coupling tests on plain-Rust slaves: the two-mass oscillator the example FMUs
//! `MassSpring` and `SpringDamperMass` will implement.

use super::*;
use crate::slave::{ScalarType, Slave, SlaveError, StepStatus, VarBatch, VarRef};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub type CallLog = Rc<RefCell<Vec<String>>>;

/// Common behaviour of the test slaves.
#[derive(Default)]
pub struct Hooks {
    pub log: CallLog,
    pub discard_above: Option<f64>,
    pub can_state: bool,
    /// canHandleVariableCommunicationStepSize is false
    pub fixed_step_only: bool,
    pub cancel_after: Option<(usize, Arc<AtomicBool>)>,
    pub step_times: Vec<(f64, f64)>,
    pub fail_set_vr: Option<u32>,
    /// From this time on, every step is discarded with fmi2Terminated (the slave ends the run).
    pub terminate_from: Option<f64>,
    /// From this time on, every step returns `fail_step_status`.
    pub fail_step_from: Option<(f64, crate::slave::FailStatus)>,
    /// Number of get and set calls (each a batch).
    pub gets: usize,
    pub sets: usize,
}

/// Dynamics: state (x, v), values by value reference.
pub trait Model {
    fn deriv(&self, x: f64, v: f64) -> (f64, f64);
    fn values(&mut self) -> &mut Vec<f64>;
    fn state(&mut self) -> (&mut f64, &mut f64);
    fn outputs(&mut self);
}

pub struct Mock<M: Model + Clone> {
    pub name: String,
    pub m: M,
    pub saved: Option<M>,
    pub hooks: Hooks,
}

/// MassSpring: vr 0 m, 1 k, 2 d, 3 force (in), 4 position, 5 velocity (out, no feedthrough).
#[derive(Clone)]
pub struct MassSpring {
    pub vals: Vec<f64>,
    pub x: f64,
    pub v: f64,
}
impl MassSpring {
    pub fn new(m: f64, k: f64, d: f64, x0: f64) -> Self {
        MassSpring {
            vals: vec![m, k, d, 0.0, x0, 0.0],
            x: x0,
            v: 0.0,
        }
    }
}
impl Model for MassSpring {
    fn deriv(&self, x: f64, v: f64) -> (f64, f64) {
        let (m, k, d, f) = (self.vals[0], self.vals[1], self.vals[2], self.vals[3]);
        (v, (-k * x - d * v + f) / m)
    }
    fn values(&mut self) -> &mut Vec<f64> {
        &mut self.vals
    }
    fn state(&mut self) -> (&mut f64, &mut f64) {
        (&mut self.x, &mut self.v)
    }
    fn outputs(&mut self) {
        self.vals[4] = self.x;
        self.vals[5] = self.v;
    }
}

/// SpringDamperMass: vr 0 m, 1 k, 2 d, 3 input_position, 4 input_velocity (in),
/// 5 coupling_force (out, direct feedthrough), 6 position, 7 velocity (out).
#[derive(Clone)]
pub struct SpringDamperMass {
    pub vals: Vec<f64>,
    pub x: f64,
    pub v: f64,
}
impl SpringDamperMass {
    pub fn new(m: f64, k: f64, d: f64) -> Self {
        SpringDamperMass {
            vals: vec![m, k, d, 0.0, 0.0, 0.0, 0.0, 0.0],
            x: 0.0,
            v: 0.0,
        }
    }
}
impl Model for SpringDamperMass {
    fn deriv(&self, x: f64, v: f64) -> (f64, f64) {
        let (m, k, d, xi, vi) = (
            self.vals[0],
            self.vals[1],
            self.vals[2],
            self.vals[3],
            self.vals[4],
        );
        (v, -(k * (x - xi) + d * (v - vi)) / m)
    }
    fn values(&mut self) -> &mut Vec<f64> {
        &mut self.vals
    }
    fn state(&mut self) -> (&mut f64, &mut f64) {
        (&mut self.x, &mut self.v)
    }
    fn outputs(&mut self) {
        let (k, d, xi, vi) = (self.vals[1], self.vals[2], self.vals[3], self.vals[4]);
        self.vals[5] = k * (self.x - xi) + d * (self.v - vi);
        self.vals[6] = self.x;
        self.vals[7] = self.v;
    }
}

impl<M: Model + Clone> Mock<M> {
    pub fn new(name: &str, m: M) -> Self {
        Mock {
            name: name.into(),
            m,
            saved: None,
            hooks: Hooks {
                can_state: true,
                ..Default::default()
            },
        }
    }
    fn note(&self, s: &str) {
        self.hooks
            .log
            .borrow_mut()
            .push(format!("{}:{s}", self.name));
    }
}

impl<M: Model + Clone> Slave for Mock<M> {
    fn name(&self) -> &str {
        &self.name
    }
    fn setup_experiment(&mut self, _: f64, _: f64) -> Result<(), SlaveError> {
        self.note("setup");
        Ok(())
    }
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError> {
        self.note("enter");
        // start values of outputs define the initial state (initial="exact" for position)
        let x0 = self.m.values().get(4).copied().unwrap_or(0.0);
        let is_ms = self.m.values().len() == 6;
        if is_ms {
            *self.m.state().0 = x0;
        }
        self.m.outputs();
        Ok(())
    }
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError> {
        self.note("exit");
        Ok(())
    }
    fn get(&mut self, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError> {
        self.hooks.gets += 1;
        self.m.outputs();
        for (v, o) in batch.vars().iter().zip(out) {
            *o = self.m.values()[v.vr as usize];
        }
        Ok(())
    }
    fn set(&mut self, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError> {
        self.hooks.sets += 1;
        for (v, x) in batch.vars().iter().zip(values) {
            if self.hooks.fail_set_vr == Some(v.vr) {
                return Err(SlaveError {
                    instance: self.name.clone(),
                    call: "fmi2SetReal",
                    status: crate::slave::FailStatus::Error,
                    reason: None,
                });
            }
            self.m.values()[v.vr as usize] = *x;
        }
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepStatus, SlaveError> {
        self.hooks.step_times.push((t, h));
        if let Some((n, flag)) = &self.hooks.cancel_after {
            if self.hooks.step_times.len() >= *n {
                flag.store(true, Ordering::Relaxed);
            }
        }
        if self
            .hooks
            .terminate_from
            .is_some_and(|t_end| t + 1e-12 >= t_end)
        {
            return Ok(StepStatus::Discard);
        }
        if self.hooks.discard_above.is_some_and(|hmax| h > hmax) {
            return Ok(StepStatus::Discard);
        }
        if let Some((from, status)) = &self.hooks.fail_step_from {
            if t + 1e-12 >= *from {
                return Err(SlaveError {
                    instance: self.name.clone(),
                    call: "fmi2DoStep",
                    status: status.clone(),
                    reason: None,
                });
            }
        }
        // RK4 with 10 internal steps, inputs held
        let n = 10;
        let dt = h / n as f64;
        for _ in 0..n {
            let (x, v) = (*self.m.state().0, *self.m.state().1);
            let k1 = self.m.deriv(x, v);
            let k2 = self.m.deriv(x + 0.5 * dt * k1.0, v + 0.5 * dt * k1.1);
            let k3 = self.m.deriv(x + 0.5 * dt * k2.0, v + 0.5 * dt * k2.1);
            let k4 = self.m.deriv(x + dt * k3.0, v + dt * k3.1);
            let (xs, vs) = self.m.state();
            *xs = x + dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            *vs = v + dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        self.m.outputs();
        Ok(StepStatus::Ok)
    }
    fn terminate_requested(&mut self) -> bool {
        self.hooks.terminate_from.is_some()
    }
    fn can_save_state(&self) -> bool {
        self.hooks.can_state
    }
    fn can_vary_step(&self) -> bool {
        !self.hooks.fixed_step_only
    }
    fn save_state(&mut self) -> Result<(), SlaveError> {
        self.saved = Some(self.m.clone());
        Ok(())
    }
    fn restore_state(&mut self) -> Result<(), SlaveError> {
        if let Some(s) = &self.saved {
            self.m = s.clone();
        }
        self.note("restore");
        Ok(())
    }
    fn terminate(&mut self) -> Result<(), SlaveError> {
        self.note("terminate");
        Ok(())
    }
}

fn r(vr: u32) -> VarRef {
    VarRef::real(vr)
}

/// MassSpring (x0 = 0.1 m) coupled to SpringDamperMass; `order` as given.
pub fn two_mass_plan(alg: Algorithm, order: Vec<usize>, h: f64, stop: f64) -> CouplingPlan {
    let conn = |fi, f, ti, t, l: &str| PlanConnection {
        from_instance: fi,
        from: r(f),
        to_instance: ti,
        to: r(t),
        label: l.into(),
        feedthrough: false,
        source_depends_on_inputs: true,
        conversion: None,
    };
    CouplingPlan {
        start_time: 0.0,
        stop_time: stop,
        step: h,
        instances: vec![
            PlanInstance {
                name: "ms".into(),
                step_multiple: 1,
                parameters: vec![(r(0), 1.0), (r(1), 100.0), (r(2), 0.5), (r(4), 0.1)],
                parameter_names: vec![],
            },
            PlanInstance {
                name: "sdm".into(),
                step_multiple: 1,
                parameters: vec![(r(0), 0.5), (r(1), 200.0), (r(2), 1.0)],
                parameter_names: vec!["m".into(), "k".into(), "d".into()],
            },
        ],
        connections: vec![
            conn(0, 4, 1, 3, "ms.position"),
            conn(0, 5, 1, 4, "ms.velocity"),
            conn(1, 5, 0, 3, "sdm.coupling_force"),
        ],
        algorithm: alg,
        order,
        record: vec![
            Recorded {
                instance: 0,
                var: r(4),
                label: "ms.position [m]".into(),
                info: Default::default(),
            },
            Recorded {
                instance: 1,
                var: r(6),
                label: "sdm.position [m]".into(),
                info: Default::default(),
            },
            Recorded {
                instance: 0,
                var: r(3),
                label: "ms.force [N]".into(),
                info: Default::default(),
            },
        ],
        init_sweeps: 3,
        max_step_halvings: 0,
        strings: vec![],
    }
}

fn slaves() -> (Mock<MassSpring>, Mock<SpringDamperMass>) {
    (
        Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0)),
        Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0)),
    )
}

/// Monolithic reference: RK4 with a small step on the coupled 4-state system.
fn reference(stop: f64) -> (f64, f64) {
    let (m1, k1, d1, m2, k2, d2) = (1.0, 100.0, 0.5, 0.5, 200.0, 1.0);
    let f = |s: [f64; 4]| {
        let fc = k2 * (s[2] - s[0]) + d2 * (s[3] - s[1]);
        [s[1], (-k1 * s[0] - d1 * s[1] + fc) / m1, s[3], -fc / m2]
    };
    let mut s = [0.1, 0.0, 0.0, 0.0];
    let n = (stop / 1e-5).round() as usize;
    let h = stop / n as f64;
    for _ in 0..n {
        let a = f(s);
        let b = f(std::array::from_fn(|i| s[i] + 0.5 * h * a[i]));
        let c = f(std::array::from_fn(|i| s[i] + 0.5 * h * b[i]));
        let d = f(std::array::from_fn(|i| s[i] + h * c[i]));
        s = std::array::from_fn(|i| s[i] + h / 6.0 * (a[i] + 2.0 * b[i] + 2.0 * c[i] + d[i]));
    }
    (s[0], s[2])
}

fn run(plan: &CouplingPlan) -> (SimOutput, Mock<MassSpring>, Mock<SpringDamperMass>) {
    let (mut a, mut b) = slaves();
    let out = simulate(plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap();
    (out, a, b)
}

fn final_error(plan: &CouplingPlan) -> f64 {
    let (out, _, _) = run(plan);
    let (x1, x2) = reference(plan.stop_time);
    let last = out.rows().last().unwrap().to_vec();
    (last[1] - x1).abs().max((last[2] - x2).abs())
}

#[test]
fn both_algorithms_converge_to_the_monolithic_solution() {
    for alg in [Algorithm::Jacobi, Algorithm::GaussSeidel] {
        let e1 = final_error(&two_mass_plan(alg, vec![0, 1], 2e-3, 1.0));
        let e2 = final_error(&two_mass_plan(alg, vec![0, 1], 1e-3, 1.0));
        // first-order coupling error: halving h roughly halves the error
        assert!(e2 < 0.7 * e1 && e2 > 0.3 * e1, "{alg:?}: {e1} -> {e2}");
        assert!(e2 < 5e-3, "{alg:?}: {e2}");
    }
}

#[test]
fn gauss_seidel_in_feedthrough_order_beats_jacobi() {
    let ej = final_error(&two_mass_plan(Algorithm::Jacobi, vec![0, 1], 2e-3, 1.0));
    let eg = final_error(&two_mass_plan(
        Algorithm::GaussSeidel,
        vec![0, 1],
        2e-3,
        1.0,
    ));
    assert!(eg < ej, "GS {eg} vs Jacobi {ej}");
}

#[test]
fn a_connection_converts_the_value_to_the_target_unit_and_records_the_source_in_its_own() {
    for alg in [Algorithm::GaussSeidel, Algorithm::Jacobi] {
        let mut plan = two_mass_plan(alg, vec![0, 1], 1e-3, 0.02);
        // ms.position [m] -> sdm.input_position as if that were in a unit of 1 mm, 5 mm off
        plan.connections[0].conversion = Some(UnitConversion {
            factor: 1000.0,
            offset: 5.0,
        });
        plan.record.push(Recorded {
            instance: 1,
            var: r(3),
            label: "sdm.input_position".into(),
            info: Default::default(),
        });
        let (out, _, _) = run(&plan);
        let mut rows = 0;
        for row in out.rows() {
            // ms.position is read once for the exchange and the record: recorded in metres
            assert_eq!(row[4], 1000.0 * row[1] + 5.0, "{alg:?}, t = {}", row[0]);
            rows += 1;
        }
        assert_eq!(rows, 21);
        assert_eq!(out.rows().next().unwrap()[1], 0.1);
    }
}

#[test]
fn a_conversion_that_overflows_is_named_as_such() {
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.02);
    plan.connections[0].conversion = Some(UnitConversion {
        factor: f64::MAX,
        offset: f64::MAX,
    });
    let (mut a, mut b) = slaves();
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default())
        .unwrap_err()
        .to_string();
    // the FMU's own value (0.1 m) is finite: the message says the conversion made it inf
    assert!(
        e.contains("'ms.position (converted to its input's unit: x ")
            && e.contains("not finite (inf)"),
        "{e}"
    );
}

#[test]
fn unit_conversion_by_base_units() {
    // degree Celsius (K, offset 273.15) to kelvin and back
    let c = UnitConversion::between((1.0, 273.15), (1.0, 0.0)).unwrap();
    assert_eq!(c.apply(20.0), 293.15);
    let k = UnitConversion::between((1.0, 0.0), (1.0, 273.15)).unwrap();
    assert!((k.apply(293.15) - 20.0).abs() < 1e-12);
    // km/h (1/3.6 m/s) to m/s
    let v = UnitConversion::between((1.0 / 3.6, 0.0), (1.0, 0.0)).unwrap();
    assert!((v.apply(360.0) - 100.0).abs() < 1e-12);
    // the same unit under two names: nothing to convert
    assert_eq!(UnitConversion::between((0.001, 0.0), (0.001, 0.0)), None);
}

#[test]
fn initialisation_propagates_feedthrough_outputs() {
    let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
    let (out, _, _) = run(&plan);
    let first = out.rows().next().unwrap();
    assert_eq!(first[0], 0.0);
    assert_eq!(first[1], 0.1);
    // force on ms = k2 (x2 - x1) = 200 * (0 - 0.1) = -20 N, consistent at t0
    assert!((first[3] + 20.0).abs() < 1e-12, "{}", first[3]);
}

#[test]
fn communication_points_do_not_drift_and_end_at_stop() {
    let plan = two_mass_plan(Algorithm::Jacobi, vec![0, 1], 0.1, 100.0);
    let (out, a, _) = run(&plan);
    assert_eq!(a.hooks.step_times.len(), 1000);
    for (k, &(t, _)) in a.hooks.step_times.iter().enumerate() {
        assert_eq!(t, k as f64 * 0.1, "step {k}");
    }
    let (t_last, h_last) = *a.hooks.step_times.last().unwrap();
    assert_eq!(t_last + h_last, 100.0);
    assert_eq!(out.rows().last().unwrap()[0], 100.0);
    assert_eq!(out.rows().count(), 1001);
    assert_eq!(out.summary.steps, 1000);
}

#[test]
fn step_multiples() {
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.0105);
    plan.stop_time = 0.011;
    plan.instances[1].step_multiple = 4;
    let (_, a, b) = run(&plan);
    assert_eq!(a.hooks.step_times.len(), 11);
    // sdm steps at k = 0, 4, 8; the last window is shortened to end at the stop time
    let t: Vec<(f64, f64)> = b.hooks.step_times.clone();
    assert_eq!(t.len(), 3);
    assert!((t[1].0 - 0.004).abs() < 1e-15 && (t[1].1 - 0.004).abs() < 1e-15);
    assert!((t[2].0 + t[2].1 - 0.011).abs() < 1e-15, "{t:?}");
}

#[test]
fn discard_is_retried_with_halved_steps() {
    let plan = {
        let mut p = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 4e-3, 0.2);
        p.max_step_halvings = 3;
        p
    };
    let (mut a, mut b) = slaves();
    b.hooks.discard_above = Some(1.1e-3); // needs two halvings
    let out = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap();
    assert_eq!(out.summary.rejected_steps, 2 * 50);
    // the retried run equals a plain run at h/4 with the same exchange pattern closely
    let fine = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.2);
    let (ref_out, _, _) = run(&fine);
    let last = out.rows().last().unwrap();
    let last_ref = ref_out.rows().last().unwrap();
    assert!(
        (last[1] - last_ref[1]).abs() < 1e-12,
        "{} vs {}",
        last[1],
        last_ref[1]
    );
    // and ms was restored too
    assert!(a.hooks.log.borrow().iter().any(|s| s == "ms:restore"));
}

/// FMI 2.0 allows only fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance after fmi2Error (and
/// only fmi2FreeInstance after fmi2Fatal): an instance that returned either is not
/// terminated, the others are.
#[test]
fn an_instance_that_returned_an_error_is_not_terminated() {
    use crate::slave::FailStatus;
    for status in [FailStatus::Error, FailStatus::Fatal] {
        let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.2);
        let (mut a, mut b) = slaves();
        let log = CallLog::default();
        a.hooks.log = log.clone();
        b.hooks.log = log.clone();
        b.hooks.fail_step_from = Some((0.1, status.clone()));
        let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
        assert!(e.to_string().contains("fmi2DoStep"), "{e}");
        let log = log.borrow();
        assert!(
            log.contains(&"ms:terminate".to_string()),
            "{status}: {log:?}"
        );
        assert!(
            !log.contains(&"sdm:terminate".to_string()),
            "{status}: {log:?}"
        );
    }
}

/// A run that fails keeps its history: every row up to the last point both instances
/// completed, the summary saying where and why; the plain `simulate` gives the same error. A
/// failure before the first row has no history.
#[test]
fn a_failed_run_keeps_its_history_up_to_the_failure() {
    use crate::slave::FailStatus;
    for fast in [true, false] {
        let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.2);
        let opts = RunOptions {
            general_engine: !fast,
            ..RunOptions::default()
        };
        let full = {
            let (mut a, mut b) = slaves();
            simulate(&plan, &mut [&mut a, &mut b], &opts).unwrap()
        };
        let (mut a, mut b) = slaves();
        b.hooks.fail_step_from = Some((0.1, FailStatus::Error));
        let failed = simulate_keeping_history(&plan, &mut [&mut a, &mut b], &opts).unwrap_err();
        assert!(
            failed.error.to_string().contains("fmi2DoStep"),
            "{}",
            failed.error
        );
        let history = failed.history.expect("rows before the failure");
        let width = history.header.len();
        let rows = history.data.len() / width;
        assert_eq!(history.header, full.header);
        let last_t = history.data[(rows - 1) * width];
        assert!((last_t - 0.1).abs() < 1e-9, "last row at {last_t}");
        assert_eq!(history.data[..], full.data[..rows * width], "fast {fast}");
        let f = history.summary.failed.as_ref().unwrap();
        assert_eq!(
            (f.time_s, f.error.clone()),
            (last_t, failed.error.to_string())
        );
        assert_eq!(history.summary.steps, 100);
        assert!(history.summary.to_string().contains("failed after t = 0.1"));
        let (mut a, mut b) = slaves();
        b.hooks.fail_step_from = Some((0.1, FailStatus::Error));
        let e = simulate(&plan, &mut [&mut a, &mut b], &opts).unwrap_err();
        assert_eq!(e.to_string(), failed.error.to_string());
    }
    let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.2);
    let (mut a, mut b) = slaves();
    b.hooks.fail_step_from = Some((0.0, FailStatus::Error));
    let failed =
        simulate_keeping_history(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    // the start row was recorded before the first step failed
    let history = failed.history.unwrap();
    assert_eq!(history.data.len(), history.header.len());
    assert_eq!(history.summary.steps, 0);
}

#[test]
fn discard_without_state_support_or_retry_is_an_error_and_terminates() {
    let mut plan = two_mass_plan(Algorithm::Jacobi, vec![0, 1], 4e-3, 0.2);
    plan.max_step_halvings = 3;
    let (mut a, mut b) = slaves();
    let log = CallLog::default();
    a.hooks.log = log.clone();
    b.hooks.log = log.clone();
    a.hooks.can_state = false;
    b.hooks.discard_above = Some(1e-3);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("'sdm'") && msg.contains("'ms' does not support"),
        "{msg}"
    );
    assert!(log.borrow().contains(&"ms:terminate".to_string()));
    assert!(log.borrow().contains(&"sdm:terminate".to_string()));

    plan.max_step_halvings = 0;
    let (mut a, mut b) = slaves();
    b.hooks.discard_above = Some(1e-3);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::Discarded { ref instance, .. } if instance == "sdm"));

    plan.max_step_halvings = 1;
    let (mut a, mut b) = slaves();
    b.hooks.discard_above = Some(1e-4);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(e.to_string().contains("after 1 halvings"), "{e}");
}

#[test]
fn termination_requested_by_a_slave_ends_the_run_at_the_last_completed_point() {
    for alg in [Algorithm::Jacobi, Algorithm::GaussSeidel] {
        // retry on: a terminating discard is never retried
        let mut plan = two_mass_plan(alg, vec![0, 1], 1e-2, 1.0);
        plan.max_step_halvings = 3;
        let (mut a, mut b) = slaves();
        let log = CallLog::default();
        a.hooks.log = log.clone();
        b.hooks.log = log.clone();
        b.hooks.terminate_from = Some(0.3);
        let out = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap();
        let t = out.column("time").unwrap();
        assert_eq!(t.len(), 31, "{alg:?}");
        assert!((t[30] - 0.3).abs() < 1e-12, "{alg:?}: {}", t[30]);
        let term = out.summary.terminated.clone().unwrap();
        assert_eq!(term.instance, "sdm");
        assert!((term.time_s - 0.3).abs() < 1e-12);
        assert_eq!(out.summary.steps, 30);
        assert_eq!(out.summary.rejected_steps, 0);
        assert!((out.summary.simulated_time_s - 0.3).abs() < 1e-12);
        assert!(out
            .summary
            .to_string()
            .contains("terminated by instance 'sdm' at t = 0.3"));
        // the results equal those of a run that stops at 0.3 s
        let (full, _, _) = run(&two_mass_plan(alg, vec![0, 1], 1e-2, 0.3));
        assert_eq!(out.data, full.data, "{alg:?}");
        let l = log.borrow();
        assert_eq!(l.iter().filter(|s| s.ends_with(":terminate")).count(), 2);
        assert!(!l.iter().any(|s| s.ends_with(":restore")));
    }
    // a discard without fmi2Terminated stays an error
    let plan = two_mass_plan(Algorithm::Jacobi, vec![0, 1], 1e-2, 1.0);
    let (mut a, mut b) = slaves();
    b.hooks.discard_above = Some(1e-3);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::Discarded { .. }), "{e}");
}

#[test]
fn cancel_flag_stops_and_terminates_everything() {
    let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 1.0);
    let flag = Arc::new(AtomicBool::new(false));
    let (mut a, mut b) = slaves();
    let log = CallLog::default();
    a.hooks.log = log.clone();
    b.hooks.log = log.clone();
    a.hooks.cancel_after = Some((10, flag.clone()));
    let opts = RunOptions {
        cancel: Some(&flag),
        progress: None,
        general_engine: false,
    };
    let e = simulate(&plan, &mut [&mut a, &mut b], &opts).unwrap_err();
    assert!(
        matches!(e, SimError::Cancelled { time } if (time - 0.01).abs() < 1e-12),
        "{e}"
    );
    let l = log.borrow();
    assert_eq!(l.iter().filter(|s| s.ends_with(":terminate")).count(), 2);
    assert_eq!(a.hooks.step_times.len(), 10);
}

#[test]
fn failure_during_initialisation_names_the_parameter_and_does_not_terminate() {
    let plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
    let (mut a, mut b) = slaves();
    let log = CallLog::default();
    a.hooks.log = log.clone();
    b.hooks.log = log.clone();
    b.hooks.fail_set_vr = Some(1);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "instance 'sdm': setting start value 'k' = 200 failed: instance 'sdm': fmi2SetReal failed with fmi2Error"
    );
    // ms is in initialisation mode: fmi2Terminate is not allowed there, only freeing
    assert_eq!(*log.borrow(), vec!["ms:setup", "ms:enter", "sdm:setup"]);
    // a huge value is named in its short form, not in 309 digits
    let mut plan = plan;
    for p in plan.instances[1].parameters.iter_mut() {
        if p.0.vr == 1 {
            p.1 = 1e308;
        }
    }
    let (mut a, mut b) = slaves();
    b.hooks.fail_set_vr = Some(1);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("instance 'sdm': setting start value 'k' = 1e308 failed"),
        "{e}"
    );
}

#[test]
fn non_finite_values_are_errors() {
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
    plan.instances[0].parameters[0].1 = 0.0; // zero mass -> inf acceleration
    let (mut a, mut b) = slaves();
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::NonFinite { .. }), "{e}");
}

#[test]
fn plan_checks() {
    let mut plan = two_mass_plan(Algorithm::Jacobi, vec![0, 1], 3e-3, 0.01);
    let (mut a, mut b) = slaves();
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(e.to_string().contains("not an integer multiple"), "{e}");
    plan.step = 1e-3;
    plan.order = vec![0, 0];
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(e.to_string().contains("permutation"), "{e}");
    plan.order = vec![0, 1];
    let e = simulate(&plan, &mut [&mut a], &RunOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::Plan(_)));
}

#[test]
fn topological_order_is_stable_and_breaks_cycles() {
    assert_eq!(topological_order(3, &[]), (vec![0, 1, 2], vec![]));
    assert_eq!(
        topological_order(3, &[(2, 0), (1, 0)]),
        (vec![1, 2, 0], vec![])
    );
    let (o, b) = topological_order(3, &[(0, 1), (1, 2), (2, 0)]);
    assert_eq!(o, vec![0, 1, 2]);
    assert_eq!(b, vec![0]);
    let _ = ScalarType::Integer;
}

#[test]
fn fixed_step_slave_refuses_a_shortened_last_window() {
    // 11 steps: a step multiple of 4 would end with a 3-step window
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.011);
    plan.instances[1].step_multiple = 4;
    let (mut a, mut b) = slaves();
    let log = CallLog::default();
    b.hooks.log = log.clone();
    b.hooks.fixed_step_only = true;
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, SimError::Plan(_))
            && msg.contains("'sdm'")
            && msg.contains("canHandleVariableCommunicationStepSize"),
        "{msg}"
    );
    assert!(log.borrow().is_empty(), "no call before the check: {log:?}");
    // a multiple that divides the steps is fine, and every step has the same size
    plan.stop_time = 0.012;
    let (mut a, mut b) = slaves();
    b.hooks.fixed_step_only = true;
    simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap();
    assert_eq!(b.hooks.step_times.len(), 3);
    assert!(b
        .hooks
        .step_times
        .iter()
        .all(|&(_, h)| (h - 4e-3).abs() < 1e-15));
}

#[test]
fn fixed_step_slave_is_not_retried_with_smaller_steps() {
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 4e-3, 0.2);
    plan.max_step_halvings = 3;
    let (mut a, mut b) = slaves();
    a.hooks.fixed_step_only = true;
    b.hooks.discard_above = Some(1.1e-3);
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, SimError::Discarded { ref instance, .. } if instance == "sdm")
            && msg.contains("'ms' does not support canHandleVariableCommunicationStepSize"),
        "{msg}"
    );
    // every step ms was given has the plan's size (no sub-steps were tried)
    assert!(a
        .hooks
        .step_times
        .iter()
        .all(|&(_, h)| (h - 4e-3).abs() < 1e-15));
}

#[test]
fn every_step_makes_one_get_and_one_set_call_per_slave() {
    // ms: 2 outputs to sdm, 2 recorded; sdm: 1 output to ms, 1 recorded. Per macro step each
    // slave is read once for its connected outputs and once for its recorded variables and
    // written once, whatever the number of connections (the calls of N more steps).
    for alg in [Algorithm::GaussSeidel, Algorithm::Jacobi] {
        let calls = |stop: f64| {
            let (_, a, b) = run(&two_mass_plan(alg, vec![0, 1], 0.01, stop));
            [a.hooks.gets, a.hooks.sets, b.hooks.gets, b.hooks.sets]
        };
        let (short, long) = (calls(0.1), calls(0.2));
        let per_10_steps: Vec<usize> = long.iter().zip(&short).map(|(l, s)| l - s).collect();
        assert_eq!(per_10_steps, [20, 10, 20, 10], "{alg:?}");
    }
}

/// `sdm` fed by two MassSprings (its input position from `ms1`, its input velocity from
/// `ms2`), its coupling force driving both; `sdm` steps first.
fn two_sources_plan(stop: f64) -> CouplingPlan {
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![1, 0, 2], 1e-2, stop);
    plan.instances.push(PlanInstance {
        name: "ms2".into(),
        ..plan.instances[0].clone()
    });
    let conn = |fi, f, ti, t, l: &str| PlanConnection {
        from_instance: fi,
        from: r(f),
        to_instance: ti,
        to: r(t),
        label: l.into(),
        feedthrough: false,
        source_depends_on_inputs: true,
        conversion: None,
    };
    plan.connections = vec![
        conn(0, 4, 1, 3, "ms.position"),
        conn(2, 5, 1, 4, "ms2.velocity"),
        conn(1, 5, 0, 3, "sdm.coupling_force"),
        conn(1, 5, 2, 3, "sdm.coupling_force"),
    ];
    plan.record.push(Recorded {
        instance: 2,
        var: r(4),
        label: "ms2.position [m]".into(),
        info: Default::default(),
    });
    plan
}

#[test]
fn inputs_from_several_sources_are_written_in_one_call_with_the_same_results() {
    // Gauss-Seidel in the common case writes sdm's two inputs, from the two instances that
    // step after it, in one call at the end of the macro step; the general engine writes
    // them one connection at a time. The values each instance sees at each call are the same.
    let run_with = |stop: f64, general_engine: bool| {
        let plan = two_sources_plan(stop);
        let (mut a, mut b) = slaves();
        let mut c = Mock::new("ms2", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        let opts = RunOptions {
            general_engine,
            ..RunOptions::default()
        };
        let out = simulate(&plan, &mut [&mut a, &mut b, &mut c], &opts).unwrap();
        (out, [a.hooks.sets, b.hooks.sets, c.hooks.sets])
    };
    let (fast, fast_short) = run_with(0.1, false);
    let (_, fast_long) = run_with(0.2, false);
    let (general, general_short) = run_with(0.1, true);
    let (_, general_long) = run_with(0.2, true);
    let per_10 = |long: [usize; 3], short: [usize; 3]| -> Vec<usize> {
        long.iter().zip(&short).map(|(l, s)| l - s).collect()
    };
    assert_eq!(per_10(fast_long, fast_short), [10, 10, 10]);
    assert_eq!(per_10(general_long, general_short), [10, 20, 10]);
    assert_eq!(fast.header, general.header);
    assert!(fast.data.iter().any(|x| *x != 0.0));
    let same = fast
        .data
        .iter()
        .zip(&general.data)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same && fast.data.len() == general.data.len());
    let x2 = fast.column("ms2.position [m]").unwrap();
    assert!(x2.iter().any(|x| *x != 0.0), "ms2 moved");
}

#[test]
fn a_step_that_stops_the_run_leaves_every_instance_with_the_inputs_of_one_write_per_source() {
    // ms (second in the order) stops the run at its step: sdm has stepped and its new force
    // is pending for ms2. Both engines must leave every instance with the same inputs for
    // fmi2Terminate, with a discard (an error) and with a termination request.
    let finals = |general_engine: bool, terminate: bool| {
        let plan = two_sources_plan(0.1);
        let (mut a, mut b) = slaves();
        let mut c = Mock::new("ms2", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        if terminate {
            a.hooks.terminate_from = Some(0.05);
        } else {
            a.hooks.discard_above = Some(1e-3);
        }
        let opts = RunOptions {
            general_engine,
            ..RunOptions::default()
        };
        let r = simulate(&plan, &mut [&mut a, &mut b, &mut c], &opts);
        assert_eq!(r.is_ok(), terminate, "{:?}", r.err());
        [a.m.vals.clone(), b.m.vals.clone(), c.m.vals.clone()]
    };
    for terminate in [false, true] {
        let fast = finals(false, terminate);
        assert_eq!(fast, finals(true, terminate), "terminate: {terminate}");
        // what is checked is a new force on ms2
        assert!(fast[2][3] != 0.0, "terminate: {terminate}");
    }
}

#[test]
fn an_input_driven_by_two_connections_is_refused() {
    let mut plan = two_sources_plan(0.1);
    plan.connections.push(PlanConnection {
        from_instance: 2,
        from: r(4),
        to_instance: 1,
        to: r(3),
        label: "ms2.position".into(),
        feedthrough: false,
        source_depends_on_inputs: false,
        conversion: None,
    });
    let e = check_plan(&plan, 3).unwrap_err().to_string();
    assert!(
        e.contains("instance 'sdm' is driven by two connections")
            && e.contains("ms.position")
            && e.contains("ms2.position"),
        "{e}"
    );
    // the same value reference as an input of another type is another variable
    plan.connections.last_mut().unwrap().to = VarRef {
        vr: 3,
        ty: ScalarType::Integer,
    };
    assert!(check_plan(&plan, 3).is_ok());
}

/// The results (bits, or the error) and the values each instance holds at the end, from
/// the common-case step and from the general engine, on a three-instance Gauss-Seidel plan
/// (see the proptest below).
type EngineRun = (Result<Vec<u64>, String>, [Vec<f64>; 3]);

fn common_case_and_general(
    order: Vec<usize>,
    sources: &[Option<usize>],
    integer: bool,
    stop_by: Option<(usize, bool)>,
) -> (EngineRun, EngineRun) {
    // outputs: (instance, vr); inputs: (instance, vr)
    const OUTPUTS: [(usize, u32); 7] = [(0, 4), (0, 5), (1, 5), (1, 6), (1, 7), (2, 4), (2, 5)];
    const INPUTS: [(usize, u32); 4] = [(0, 3), (1, 3), (1, 4), (2, 3)];
    let mut plan = two_sources_plan(0.05);
    plan.order = order;
    let force_read = sources.iter().flatten().any(|&k| OUTPUTS[k] == (1, 5));
    plan.connections = INPUTS
        .iter()
        .zip(sources)
        .filter_map(|(&(ti, tv), s)| {
            let (fi, fv) = OUTPUTS[(*s)?];
            Some(PlanConnection {
                from_instance: fi,
                from: r(fv),
                to_instance: ti,
                to: r(tv),
                label: format!("{fi}.{fv}"),
                // sdm's inputs feed through to its coupling force
                feedthrough: ti == 1 && force_read,
                // the coupling force is the only output that depends on an input
                source_depends_on_inputs: (fi, fv) == (1, 5),
                conversion: None,
            })
        })
        .collect();
    if integer {
        // ms's mass (1.0) as an Integer to sdm's mass
        plan.connections.push(PlanConnection {
            from_instance: 0,
            from: VarRef {
                vr: 0,
                ty: ScalarType::Integer,
            },
            to_instance: 1,
            to: VarRef {
                vr: 0,
                ty: ScalarType::Integer,
            },
            label: "ms.m".into(),
            feedthrough: false,
            source_depends_on_inputs: false,
            conversion: None,
        });
    }
    let run = |general_engine: bool| {
        let (mut a, mut b) = slaves();
        let mut c = Mock::new("ms2", MassSpring::new(1.0, 1.0, 1.0, 0.0));
        if let Some((who, terminate)) = stop_by {
            let h = &mut [&mut a.hooks, &mut b.hooks, &mut c.hooks][who];
            if terminate {
                h.terminate_from = Some(0.02);
            } else {
                h.discard_above = Some(1e-3);
            }
        }
        let opts = RunOptions {
            general_engine,
            ..RunOptions::default()
        };
        let out = simulate(&plan, &mut [&mut a, &mut b, &mut c], &opts)
            .map(|o| o.data.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
            .map_err(|e| e.to_string());
        (out, [a.m.vals.clone(), b.m.vals.clone(), c.m.vals.clone()])
    };
    (run(false), run(true))
}

/// A stale instance read again before the write that uses it: sdm steps first, ms sets its
/// input (feedthrough to sdm's coupling force) and reads nothing back, ms2 then takes sdm's
/// coupling force (order sdm, ms, ms2), and ms's own input from sdm is written again at the
/// end of the step.
#[test]
fn a_source_read_again_within_the_step_passes_on_its_fresh_outputs() {
    // inputs ms.force, sdm.input_position, sdm.input_velocity, ms2.force from outputs
    // sdm.coupling_force, ms.position, ms2.velocity, sdm.coupling_force
    let (fast, general) = common_case_and_general(
        vec![1, 0, 2],
        &[Some(2), Some(0), Some(6), Some(2)],
        false,
        None,
    );
    assert!(fast.0.is_ok());
    assert_eq!(fast, general);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 256,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// The common-case step against the general engine on random Gauss-Seidel plans over
    /// three instances: any order, each input driven or not from any output (self-connections
    /// and direct feedthrough included), optionally an Integer connection beside the Reals
    /// (written at once), optionally a step that stops the run. Same results bit for bit, same
    /// inputs held at the end.
    #[test]
    fn the_common_case_step_equals_the_general_engine_on_random_plans(
        order in proptest::sample::select(vec![
            vec![0, 1, 2], vec![0, 2, 1], vec![1, 0, 2],
            vec![1, 2, 0], vec![2, 0, 1], vec![2, 1, 0],
        ]),
        sources in proptest::collection::vec(proptest::option::of(0usize..7), 4),
        integer in proptest::bool::ANY,
        stop_by in proptest::option::of((0usize..3, proptest::bool::ANY)),
    ) {
        let (fast, general) = common_case_and_general(order, &sources, integer, stop_by);
        proptest::prop_assert_eq!(&fast.0, &general.0);
        proptest::prop_assert_eq!(&fast.1, &general.1);
    }
}

/// A slave of a direct-feedthrough chain: `Clock` outputs (vr 0) its time, `Gain` outputs
/// y = 2 u (vr 1) from its input u (vr 0) at once (direct feedthrough), `Sink` only has an
/// input (vr 0).
enum ChainKind {
    Clock,
    Gain,
    Sink,
}

struct ChainSlave {
    name: String,
    kind: ChainKind,
    vals: [f64; 2],
    t: f64,
}

impl ChainSlave {
    fn new(name: &str, kind: ChainKind) -> Self {
        ChainSlave {
            name: name.into(),
            kind,
            vals: [0.0; 2],
            t: 0.0,
        }
    }
    fn update(&mut self) {
        match self.kind {
            ChainKind::Clock => self.vals[0] = self.t,
            ChainKind::Gain => self.vals[1] = 2.0 * self.vals[0],
            ChainKind::Sink => {}
        }
    }
}

impl Slave for ChainSlave {
    fn name(&self) -> &str {
        &self.name
    }
    fn setup_experiment(&mut self, t0: f64, _: f64) -> Result<(), SlaveError> {
        self.t = t0;
        Ok(())
    }
    fn enter_initialization_mode(&mut self) -> Result<(), SlaveError> {
        Ok(())
    }
    fn exit_initialization_mode(&mut self) -> Result<(), SlaveError> {
        Ok(())
    }
    fn get(&mut self, batch: &VarBatch, out: &mut [f64]) -> Result<(), SlaveError> {
        self.update();
        for (v, o) in batch.vars().iter().zip(out) {
            *o = self.vals[v.vr as usize];
        }
        Ok(())
    }
    fn set(&mut self, batch: &VarBatch, values: &[f64]) -> Result<(), SlaveError> {
        for (v, x) in batch.vars().iter().zip(values) {
            self.vals[v.vr as usize] = *x;
        }
        Ok(())
    }
    fn do_step(&mut self, t: f64, h: f64) -> Result<StepStatus, SlaveError> {
        self.t = t + h;
        self.update();
        Ok(StepStatus::Ok)
    }
    fn can_save_state(&self) -> bool {
        false
    }
    fn can_vary_step(&self) -> bool {
        true
    }
    fn save_state(&mut self) -> Result<(), SlaveError> {
        Ok(())
    }
    fn restore_state(&mut self) -> Result<(), SlaveError> {
        Ok(())
    }
    fn terminate(&mut self) -> Result<(), SlaveError> {
        Ok(())
    }
}

/// clock -> gain (direct feedthrough) -> sink, the gain stepped first: its output depends
/// on the clock's, which changes after the gain has stepped.
fn chain_plan(alg: Algorithm) -> CouplingPlan {
    let conn = |fi, f, ti, t, feedthrough, l: &str| PlanConnection {
        from_instance: fi,
        from: r(f),
        to_instance: ti,
        to: r(t),
        label: l.into(),
        feedthrough,
        // the gain's output depends on its input; the clock has none
        source_depends_on_inputs: fi == 0,
        conversion: None,
    };
    let inst = |name: &str| PlanInstance {
        name: name.into(),
        step_multiple: 1,
        parameters: vec![],
        parameter_names: vec![],
    };
    CouplingPlan {
        start_time: 0.0,
        stop_time: 1.0,
        step: 0.1,
        instances: vec![inst("gain"), inst("clock"), inst("sink")],
        connections: vec![
            conn(1, 0, 0, 0, true, "clock.t"),
            conn(0, 1, 2, 0, false, "gain.y"),
        ],
        algorithm: alg,
        order: vec![0, 1, 2],
        record: vec![Recorded {
            instance: 2,
            var: r(0),
            label: "sink.u".into(),
            info: Default::default(),
        }],
        init_sweeps: 3,
        max_step_halvings: 0,
        strings: vec![],
    }
}

#[test]
fn gauss_seidel_reads_direct_feedthrough_outputs_again_after_setting_inputs() {
    let run_chain = |alg| {
        let mut g = ChainSlave::new("gain", ChainKind::Gain);
        let mut c = ChainSlave::new("clock", ChainKind::Clock);
        let mut s = ChainSlave::new("sink", ChainKind::Sink);
        let out = simulate(
            &chain_plan(alg),
            &mut [&mut g, &mut c, &mut s],
            &RunOptions::default(),
        )
        .unwrap();
        out.column("sink.u").unwrap()
    };
    let gs = run_chain(Algorithm::GaussSeidel);
    let jacobi = run_chain(Algorithm::Jacobi);
    assert_eq!(gs.len(), 11);
    for (k, (&g, &j)) in gs.iter().zip(&jacobi).enumerate() {
        let t = k as f64 * 0.1;
        // the exact coupled answer: sink.u = 2 t at every point
        assert!((g - 2.0 * t).abs() < 1e-12, "GS at t = {t}: {g}");
        // Jacobi passes the gain's output computed from the clock one step earlier
        if k > 0 {
            assert!(
                (j - 2.0 * (t - 0.1)).abs() < 1e-12,
                "Jacobi at t = {t}: {j}"
            );
        }
    }
}

#[test]
fn a_recorded_connected_output_is_not_read_again_while_its_slave_is_unchanged() {
    // sdm.coupling_force is connected and recorded. Gauss-Seidel (ms, sdm): after sdm's step
    // and read nothing is called on sdm before the record, so the record takes the value read
    // for the exchange (one get per step); ms has its force set after its read, so it is read
    // again. Jacobi sets sdm's inputs after reading it: read again.
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 0.01, 0.1);
    plan.record[1] = Recorded {
        instance: 1,
        var: r(5),
        label: "sdm.coupling_force [N]".into(),
        info: Default::default(),
    };
    for (alg, sdm_gets) in [(Algorithm::GaussSeidel, 10), (Algorithm::Jacobi, 20)] {
        plan.algorithm = alg;
        let calls = |stop: f64| {
            let mut p = plan.clone();
            p.stop_time = stop;
            let (out, a, b) = run(&p);
            (out, [a.hooks.gets, b.hooks.gets])
        };
        let ((_, short), (out, long)) = (calls(0.1), calls(0.2));
        assert_eq!(
            [long[0] - short[0], long[1] - short[1]],
            [20, sdm_gets],
            "{alg:?}"
        );
        if alg == Algorithm::GaussSeidel {
            // the force recorded on ms is the one sdm gave at every point
            let f_sdm = out.column("sdm.coupling_force [N]").unwrap();
            let f_ms = out.column("ms.force [N]").unwrap();
            assert_eq!(f_sdm.len(), 21);
            assert_eq!(f_sdm, f_ms);
            assert!(f_sdm.iter().any(|f| *f != 0.0));
        }
    }
}

#[test]
fn a_step_below_the_time_resolution_of_the_run_is_refused() {
    use super::step_below_resolution;
    // 1e16 + 1e-3 == 1e16: points would repeat
    let why = step_below_resolution(1e16, 1e16 + 2.0, 1e-3).unwrap();
    assert!(why.contains("advances time by 0 s"), "{why}");
    // a Unix-time start with 1 ms steps still advances by 1 ms (to 2e-4 of it)
    assert!(step_below_resolution(1.7e9, 1.7e9 + 10.0, 1e-3).is_none());
    assert!(step_below_resolution(0.0, 10.0, 1e-3).is_none());
    assert!(step_below_resolution(-5.0, 0.0, 1e-9).is_none());
    let mut plan = two_mass_plan(Algorithm::GaussSeidel, vec![0, 1], 1e-3, 0.01);
    plan.start_time = 1e16;
    plan.stop_time = 1e16 + 2.0;
    let mut a = Mock::new("ms", MassSpring::new(1.0, 1.0, 1.0, 0.0));
    let mut b = Mock::new("sdm", SpringDamperMass::new(1.0, 1.0, 1.0));
    let e = simulate(&plan, &mut [&mut a, &mut b], &RunOptions::default()).unwrap_err();
    assert!(e.to_string().contains("below the time resolution"), "{e}");
}
