//! The glue computes a model's outputs after a step only when the step did not already.
#![allow(clippy::unwrap_used)]

use model_description::{
    rust_component, value_reference, Component, DefaultExperiment, Diagnostics, FmuModel,
    InstanceContext, ModelError, ModelInfo, Status, StepError, Variable,
};
use serde::{Deserialize, Serialize};

/// y = k u + x, where the state x grows by u per step; counts the glue's `update_outputs` calls.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Counting<const COMPUTES: bool> {
    u: f64,
    x: f64,
    y: f64,
    updates: u32,
}

impl<const COMPUTES: bool> FmuModel for Counting<COMPUTES> {
    const INFO: ModelInfo = ModelInfo {
        name: "Counting",
        description: "counts output updates",
        author: "test",
        version: "0",
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 0.1,
        },
        documentation_html: "",
        resources: &[],
    };

    fn variables() -> Vec<Variable<Self>> {
        let mut v: Vec<Variable<Self>> = Vec::new();
        model_description::declare! { v;
            /// Input
            input "u" => u;
            /// Output, direct feedthrough of u
            output "y" [depends_on = &["u"]] => y;
            /// Number of update_outputs calls so far
            output "updates" [depends_on = &["u"]] => updates;
        }
        v
    }

    fn instantiate(_ctx: &InstanceContext) -> Result<Self, ModelError> {
        Ok(Counting {
            u: 0.0,
            x: 0.0,
            y: 0.0,
            updates: 0,
        })
    }

    fn exit_initialization(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        Ok(())
    }

    fn update_outputs(&mut self, _diag: &mut Diagnostics) -> Result<(), ModelError> {
        self.updates += 1;
        self.y = 2.0 * self.u + self.x;
        Ok(())
    }

    fn do_step(&mut self, _t: f64, _h: f64, _diag: &mut Diagnostics) -> Result<(), StepError> {
        self.x += self.u;
        if COMPUTES {
            self.y = 2.0 * self.u + self.x;
        }
        Ok(())
    }

    fn step_computes_outputs(&self) -> bool {
        COMPUTES
    }
}

fn started<M: FmuModel>() -> Component {
    let (mut c, _log) = rust_component::<M>(InstanceContext::default()).unwrap();
    assert_eq!(c.setup_experiment(0.0, None), Status::Ok);
    assert_eq!(c.enter_initialization_mode(), Status::Ok);
    assert_eq!(c.exit_initialization_mode(), Status::Ok);
    c
}

/// (y after each of three steps with u = 1, 2, 3 set before the step, number of updates).
fn run<const COMPUTES: bool>() -> (Vec<f64>, Vec<u32>) {
    let mut c = started::<Counting<COMPUTES>>();
    let (u, y) = (
        value_reference::<Counting<COMPUTES>>("u").unwrap(),
        value_reference::<Counting<COMPUTES>>("y").unwrap(),
    );
    let (mut ys, mut counts) = (Vec::new(), Vec::new());
    let n = value_reference::<Counting<COMPUTES>>("updates").unwrap();
    // read after y: the outputs are current, the read computes nothing
    let updates = |c: &mut Component| {
        let mut k = [0];
        assert_eq!(c.get_integer(&[n], &mut k), Status::Ok);
        u32::try_from(k[0]).unwrap()
    };
    for (k, input) in [1.0, 2.0, 3.0].into_iter().enumerate() {
        assert_eq!(c.set_real(&[u], &[input]), Status::Ok);
        assert_eq!(c.do_step(k as f64 * 0.1, 0.1), Status::Ok);
        let mut out = [f64::NAN];
        assert_eq!(c.get_real(&[y], &mut out), Status::Ok);
        // read twice: the second read computes nothing
        assert_eq!(c.get_real(&[y], &mut out), Status::Ok);
        ys.push(out[0]);
        counts.push(updates(&mut c));
    }
    // an input set after the step is seen by the next read (direct feedthrough)
    assert_eq!(c.set_real(&[u], &[10.0]), Status::Ok);
    let mut out = [f64::NAN];
    assert_eq!(c.get_real(&[y], &mut out), Status::Ok);
    ys.push(out[0]);
    counts.push(updates(&mut c));
    (ys, counts)
}

#[test]
fn outputs_a_step_computed_are_not_computed_again_and_inputs_still_count() {
    let (y_glue, n_glue) = run::<false>();
    let (y_step, n_step) = run::<true>();
    // x = 1, 3, 6; y = 2 u + x
    assert_eq!(y_glue, [3.0, 7.0, 12.0, 26.0]);
    assert_eq!(y_step, y_glue);
    // exit_initialization computes the outputs once; then one update per read after a step,
    // or none when the step computed them; the input set at the end always costs one
    assert_eq!(n_glue, [2, 3, 4, 5]);
    assert_eq!(n_step, [1, 1, 1, 2]);
}
