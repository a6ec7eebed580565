use cdpr_core::model::CableModel;
use cdpr_core::scenario::{ModelKind, Scenario};
use cdpr_fe::Fe;
use cdpr_lumped::Lumped;
fn main() {
    for n in [10i64, 40, 100, 300, 1000] {
        for kind in [ModelKind::Lumped, ModelKind::Fe] {
            let mut s = Scenario::paper();
            s.model.kind = kind;
            s.model.elements = Some(n);
            let mut m: Box<dyn CableModel> = match kind {
                ModelKind::Lumped => Box::new(Lumped::new(&s).unwrap()),
                _ => Box::new(Fe::new(&s).unwrap()),
            };
            let t0 = std::time::Instant::now();
            let eq = m.equilibrium(0.5, 200.0);
            match eq {
                Ok(eq) => println!(
                    "{kind} N={n}: {:?} it {} res {:e} z_P {} F0 {:e}",
                    t0.elapsed(),
                    eq.iterations,
                    eq.residual,
                    m.effector(&eq.state).position.y,
                    eq.force
                ),
                Err(e) => println!("{kind} N={n}: error {e}"),
            }
        }
    }
}
