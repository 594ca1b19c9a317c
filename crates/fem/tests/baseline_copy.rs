//! The FEM's hot loops are compiled twice, for AVX2 and for baseline x86-64 (what processors
//! without AVX2 and other architectures run), and the processor picks at run time
//! (`flexstar_numerics::dispatch_avx2!`, docs/fem.md section 6). Both copies compute the same
//! IEEE operations in the same order, so a whole run must give the same numbers bit for bit
//! whichever copy ran: this test runs both (its own process: the switch is process-wide).

use flexstar_model::{catalogue, FemSettings, Response};
use flexstar_numerics::lanes::force_baseline;

fn bits(r: &Response) -> Vec<u64> {
    let mut out: Vec<u64> = r.t.iter().map(|x| x.to_bits()).collect();
    for group in [&r.w_g, &r.w_tip, &r.fa] {
        for c in group.iter() {
            out.extend(c.iter().map(|x| x.to_bits()));
        }
    }
    for c in &r.extra {
        out.extend(c.values.iter().map(|x| x.to_bits()));
    }
    out
}

#[test]
fn baseline_and_avx2_copies_give_the_same_run() {
    // case 3 (three different slider motions), 105 elements: batches of four with a partial
    // last one, 0.05 s at the default step
    let mut exp = catalogue::paper_case(3);
    exp.time.t_end = 0.05;
    let settings = FemSettings {
        elements: 105,
        ..FemSettings::default()
    };
    force_baseline(false);
    let problem = exp.problem().unwrap();
    let (chosen, s1) = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| (s.response, s.stats))
        .expect("run with the processor's copy");
    force_baseline(true);
    // the switch the dispatched bodies read (the counters of numerics' own test show that they
    // obey it): every body below runs its baseline copy
    assert!(!flexstar_numerics::lanes::has_avx2());
    let problem = exp.problem().unwrap();
    let (baseline, s2) = flexstar_fem::solve(&problem, &settings, flexstar_drive::SolveRequest::motion())
        .map(|s| (s.response, s.stats))
        .expect("run with the baseline copy");
    force_baseline(false);
    assert_eq!(s1, s2, "work counters");
    assert!(s1.steps == 100 && s1.newton_iterations >= 200);
    assert_eq!(bits(&chosen), bits(&baseline), "the two copies must agree bit for bit");
    // and the run is not trivial: the tips move and the forces are not zero
    assert!(chosen.w_tip[0].iter().any(|w| w.abs() > 1e-6) && chosen.fa[0].iter().any(|f| f.abs() > 1e-3));
}
