//! CPU time of a direct AMM run against the inverse run of the same case (issue 10 item 6), read
//! from /proc/thread-self/schedstat (time on a CPU, so that the load of a shared machine counts
//! less than in wall-clock benches). `cargo run --release -p flexstar-amm --example direct_cost`
use flexstar_amm::{solve, solve_direct};
use flexstar_drive::{ForceTable, Servo};
use flexstar_model::catalogue::paper_case;
use flexstar_model::{AmmSettings, ModeFamily};

fn cpu_ns() -> u64 {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    s.split_whitespace().next().and_then(|v| v.parse().ok()).unwrap_or(0)
}

fn best<F: FnMut()>(mut f: F) -> f64 {
    (0..7)
        .map(|_| {
            let t0 = cpu_ns();
            f();
            (cpu_ns() - t0) as f64 * 1e-6
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let accurate = AmmSettings {
        modes: Some(53),
        ..AmmSettings::accurate()
    };
    for case in 1..=4 {
        let exp = paper_case(case);
        for (label, settings) in [("N=25 paper", exp.amm.clone()), ("N=53 accurate", accurate.clone())] {
            let settings = if label.starts_with("N=25") {
                AmmSettings {
                    modes: Some(25),
                    ..settings
                }
            } else {
                settings
            };
            let _ = ModeFamily::FreeFree;
            let inverse = solve(&exp, &settings).unwrap();
            let fa = (0..inverse.len())
                .map(|k| [inverse.fa[0][k], inverse.fa[1][k], inverse.fa[2][k]])
                .collect();
            let table = ForceTable::new(inverse.t.clone(), fa).unwrap();
            let (kp, kd) = Servo::gains_from_bandwidth(exp.robot.mpp_mpa, 20.0, 0.7);
            let servo = Servo {
                kp: [kp; 3],
                kd: [kd; 3],
                rigid_feedforward: true,
                reference: exp.trajectory.clone(),
                params: exp.robot,
            };
            let ti = best(|| {
                solve(&exp, &settings).unwrap();
            });
            let tf = best(|| {
                solve_direct(&exp, &settings, &table).unwrap();
            });
            let ts = best(|| {
                solve_direct(&exp, &settings, &servo).unwrap();
            });
            println!("case {case} {label:14} inverse {ti:7.1} ms  direct/forces {tf:7.1} ms ({:.2} x)  direct/servo 20 Hz {ts:7.1} ms ({:.2} x)", tf / ti, ts / ti);
        }
    }
}
