//! Times the log density and its gradient at K = 9 (a quick check; the criterion benches in
//! `benches/` are the measurement of record).
use std::time::Instant;

use motorcal::bayes::ModelSettings;
use motorcal::density::LogDensity;
use motorcal::study::Problem;

fn main() {
    let problem = Problem::paper(1).unwrap();
    let mut post = problem.posterior(&ModelSettings::bm2(9)).unwrap();
    let mut x = post.initial_point().unwrap();
    let n = 20_000;
    let forward = post.forward(0).clone();
    let mut out = vec![0.0; forward.n_outputs()];
    let t = Instant::now();
    for i in 0..n {
        forward
            .simulate(&[0.1 + 1e-9 * (i % 3) as f64], &mut out)
            .unwrap();
    }
    let solve = t.elapsed().as_secs_f64() / n as f64 * 1e6;
    let t = Instant::now();
    for i in 0..n {
        x[0] = 0.1 + 1e-9 * (i % 3) as f64;
        post.log_density(&x).unwrap();
    }
    let value = t.elapsed().as_secs_f64() / n as f64 * 1e6;
    let mut g = vec![0.0; x.len()];
    let t = Instant::now();
    for i in 0..n {
        x[0] = 0.1 + 1e-9 * (i % 3) as f64;
        post.log_density_and_gradient(&x, &mut g).unwrap();
    }
    let gradient = t.elapsed().as_secs_f64() / n as f64 * 1e6;
    println!("f64 solve {solve:.1} µs, log density {value:.1} µs, with gradient {gradient:.1} µs");
    println!(
        "gradient / solve = {:.2}, gradient / density = {:.2}",
        gradient / solve,
        gradient / value
    );
}
