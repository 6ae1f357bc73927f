//! The coach physics coupled to four hydraulic passive dampers in one process, as the
//! end-to-end tests of the coach's non-linear behaviour and EN 14363 assessment run it.

use fmu_damper::{SemiActiveDamper, SemiActiveInputs};
use fmu_vehicle::{Inputs, Outputs, Vehicle, VehicleParams};

/// Runs the coach of `params` with the seed's passive reference damper (fmu-damper at a fixed
/// 30 % opening) on all four damper ports, co-simulation style: each step the dampers step on
/// the vehicle's last outputs, then the vehicle steps on their forces. Calls `record` with the
/// vehicle's outputs after each of the `steps` steps of `h_s`.
pub fn run_with_passive_dampers(
    params: VehicleParams,
    h_s: f64,
    steps: usize,
    mut record: impl FnMut(&Outputs),
) -> Result<(), String> {
    let mut vehicle = Vehicle::new(params).map_err(|e| e.to_string())?;
    let mut dampers = [0; 4].map(|_| SemiActiveDamper::passive_reference());
    let mut inputs = Inputs::default();
    let mut out = vehicle.outputs(&inputs).map_err(|e| e.to_string())?;
    for _ in 0..steps {
        for (d, damper) in dampers.iter_mut().enumerate() {
            let damper = damper.as_mut().map_err(|e| e.to_string())?;
            let o = damper
                .step(
                    h_s,
                    &SemiActiveInputs {
                        elongation_m: out.damper[d].elongation_m,
                        elongation_velocity_mps: out.damper[d].elongation_velocity_mps,
                        valve_command_v: 0.0,
                    },
                )
                .map_err(|e| e.to_string())?;
            inputs.damper_force_n[d] = o.force_n;
        }
        out = vehicle.step(h_s, &inputs).map_err(|e| e.to_string())?;
        record(&out);
    }
    Ok(())
}
