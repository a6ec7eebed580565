//! The lumped right-hand side must not allocate: a counting global allocator, in its own test
//! binary, watches 1000 evaluations.

use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::scenario::Scenario;
use cdpr_lumped::{Lumped, Params};

#[global_allocator]
static GLOBAL: cdpr_testing::CountingAllocator = cdpr_testing::CountingAllocator;

#[test]
fn rhs_does_not_allocate() {
    let scenario = Scenario::paper();
    let mut model = Lumped::new(&scenario, Params::default()).unwrap();
    let eq = model.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
    let mut rate = vec![0.0; model.state_len()];
    let mut energy = 0.0;
    let before = cdpr_testing::allocations();
    for k in 0..1000 {
        model.rhs(k as f64 * 1e-6, &eq.state, &[100.0, 100.0], &mut rate);
        model.event_functions(&eq.state, &mut [0.0; 6]);
        energy += model.reel_speeds(&eq.state)[0];
    }
    let after = cdpr_testing::allocations();
    assert_eq!(after - before, 0, "allocations in 1000 RHS evaluations");
    assert!(energy.is_finite());
}
