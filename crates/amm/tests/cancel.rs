//! A stop on request: with the thread's cancel token set, the AMM returns `Cancelled` at the first
//! output time (the solver polls the token once per output interval) instead of a response.

#[allow(unused_imports)]
use crate::common;

use flexstar_amm::AmmError;
use flexstar_model::{cancel, Cancel, ModeFamily, RobotParams};

#[test]
fn a_set_cancel_token_stops_the_run_at_the_first_output_time() {
    let exp = common::quintic(RobotParams::paper(), 0.05);
    let token = Cancel::new();
    token.cancel();
    let settings = common::settings(ModeFamily::SlideFree, 4, None);
    match cancel::with_cancel(Some(&token), || common::motion_response(&exp, &settings)) {
        Err(AmmError::Cancelled { t }) => assert_eq!(t, exp.time.dt_out),
        other => panic!("expected Cancelled, got {:?}", other.map(|r| r.t.len())),
    }
    // without the token the same run completes
    assert!(common::motion_response(&exp, &settings).is_ok());
}
