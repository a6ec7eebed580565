use cdpr_core::closed_loop::{ClosedLoop, RunOptions, simulate_reusing};
use cdpr_core::model::CableModel;
use cdpr_core::scenario::{IntegratorKind, ModelKind, Scenario};
use cdpr_fe::Fe;
use cdpr_lumped::Lumped;
fn main() {
    let kind = if std::env::args().nth(1).as_deref() == Some("lumped") {
        ModelKind::Lumped
    } else {
        ModelKind::Fe
    };
    let sp: f64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1e-4);
    let mut s = Scenario::paper();
    s.model.kind = kind;
    s.simulation.integrator = IntegratorKind::Implicit;
    s.simulation.sample_period = sp;
    let opts = RunOptions::from(&s);
    let mut buffer = Vec::new();
    for _ in 0..3 {
        let model: Box<dyn CableModel + Send> = match kind {
            ModelKind::Lumped => Box::new(Lumped::new(&s).unwrap()),
            _ => Box::new(Fe::new(&s).unwrap()),
        };
        let mut sys = ClosedLoop::new(model, &s);
        let t0 = std::time::Instant::now();
        let run =
            simulate_reusing(&mut sys, &opts, std::mem::take(&mut buffer), &mut |_| {}).unwrap();
        eprintln!("{:?} {:?}", t0.elapsed(), run.stats);
        buffer = run.series.into_buffer();
    }
}
