use seqsmooth::{Engine, ExpandingMemory, FadingMemory, FixedMemory, PolynomialFilter};
fn run(name: &str, mut f: Box<dyn PolynomialFilter>, ts: &[f64], ys: &[f64]) {
    let mut last = None;
    for (&t, &y) in ts.iter().zip(ys) {
        if let Err(e) = f.update(t, y) {
            println!("{name}: error {e}");
            return;
        }
        last = f.estimate_at(t);
    }
    println!("{name}: {:?}", last.map(|s| s.derivatives));
}
fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let (t0, dt, y0, dy, tau) = (args[0], args[1], args[2], args[3], args[4]);
    let ts: Vec<f64> = (0..8).map(|i| t0 + dt * i as f64).collect();
    let ys: Vec<f64> = (0..8)
        .map(|i| y0 + dy * (i as f64) + dy * 0.1 * ((i * i) as f64))
        .collect();
    for e in [Engine::Exact, Engine::Gain] {
        run(
            &format!("expanding {e:?}"),
            Box::new(ExpandingMemory::new(2, e).unwrap()),
            &ts,
            &ys,
        );
        run(
            &format!("fading {e:?}"),
            Box::new(FadingMemory::new(2, 0.9, tau, e).unwrap()),
            &ts,
            &ys,
        );
    }
    for fe in [
        seqsmooth::FixedEngine::Direct,
        seqsmooth::FixedEngine::Sliding,
    ] {
        run(
            &format!("fixed {fe:?}"),
            Box::new(FixedMemory::new(2, 5, fe).unwrap()),
            &ts,
            &ys,
        );
    }
}
