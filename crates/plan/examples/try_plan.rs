fn main() {
    let path = std::env::args().nth(1).unwrap();
    let cfg = flexstar_plan::read_plan_config(std::path::Path::new(&path)).unwrap();
    let p = flexstar_plan::plan(&cfg).unwrap();
    println!("plain |r| {:.3e} peak {:.3e}", p.plain.norm(), p.plain.window_peak_m);
    println!("plan  |r| {:.3e} peak {:.3e}", p.eval.norm(), p.eval.window_peak_m);
    println!(
        "N {} f1 {:.3} W {:.3} evals {} wall {:.2} reason {}",
        p.modes, p.f1_hz, p.window_s, p.evaluations, p.wall_s, p.reason
    );
    for t in &p.trace {
        println!("{:?}", t);
    }
    println!("x {:?}", p.x);
}
