//! The FE right-hand side must not allocate: a counting global allocator, in its own test binary,
//! watches 1000 evaluations of the model and of the closed loop around it.

use cdpr_core::closed_loop::ClosedLoop;
use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::scenario::Scenario;
use cdpr_fe::{Fe, Params};
use cdpr_numerics::OdeSystem;

#[global_allocator]
static GLOBAL: cdpr_testing::CountingAllocator = cdpr_testing::CountingAllocator;

#[test]
fn rhs_does_not_allocate() {
    let scenario = Scenario::paper();
    let mut model = Fe::new(&scenario, Params::default()).unwrap();
    let eq = model.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
    let mut rate = vec![0.0; model.state_len()];
    let mut sys =
        ClosedLoop::new(Fe::new(&scenario, Params::default()).unwrap(), &scenario).unwrap();
    let (y, _) = sys.initial_state().unwrap();
    let mut dy = vec![0.0; y.len()];
    let mut check = 0.0;
    let before = cdpr_testing::allocations();
    for k in 0..1000 {
        model.rhs(k as f64 * 1e-6, &eq.state, &[100.0, 100.0], &mut rate);
        sys.rhs(k as f64 * 1e-4, &y, &mut dy);
        check += model.reel_speeds(&eq.state)[0] + rate[0] + dy[0];
    }
    let after = cdpr_testing::allocations();
    assert_eq!(after - before, 0, "allocations in 1000 RHS evaluations");
    assert!(check.is_finite());
}
