//! scratch (not committed): RMS of the true XTE by distance along each pass.
use agsteer::config::TrackerChoice;
use agsteer::demo::envelope::{cell_config, Calibration, MATRIX};
use agsteer::demo::{run, DemoOptions};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let var = MATRIX.iter().find(|v| v.name == a[1]).expect("variation");
    let extra: Vec<String> = a[3..].to_vec();
    let cfg0 = cell_config(std::path::Path::new(&a[2]), var, &[], Calibration::Truth).unwrap();
    let cfgp = cell_config(std::path::Path::new(&a[2]), var, &extra, Calibration::Truth).unwrap();
    let bins = [10.0, 15.0, 20.0, 30.0, 50.0, 100.0, 1e9];
    for t in [
        TrackerChoice::Predictive,
        TrackerChoice::PurePursuit,
        TrackerChoice::Stanley,
    ] {
        let mut cfg = if t == TrackerChoice::Predictive {
            cfgp.clone()
        } else {
            cfg0.clone()
        };
        cfg.track.kind = t;
        let opts = DemoOptions {
            record_work: true,
            ..DemoOptions::default()
        };
        let r = run(&cfg, &opts, &mut |_| {}, &mut |_, _| {}).unwrap();
        if std::env::var("GEOM").is_ok() {
            for (i, p) in r.work.iter().enumerate() {
                let (a, b) = (p.samples.first().unwrap(), p.samples.last().unwrap());
                println!(
                    "{} pass {i}: t {:.1}-{:.1} ({:.1},{:.1}) -> ({:.1},{:.1}) xte0 {:.2}",
                    t.name(),
                    a.t,
                    b.t,
                    a.pos.x,
                    a.pos.y,
                    b.pos.x,
                    b.pos.y,
                    a.xte_m * 100.0
                );
            }
            continue;
        }
        if std::env::var("TAIL").is_ok() {
            print!("{:<13}", t.name());
            for p in &r.work {
                let v: Vec<f64> = p
                    .samples
                    .iter()
                    .filter(|x| x.along_m >= 10.0 && x.along_m < 20.0)
                    .map(|x| x.xte_m)
                    .collect();
                let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
                print!(" {:.2}", rms * 100.0);
            }
            println!();
            continue;
        }
        if let Ok(k) = std::env::var("PASS") {
            let k: usize = k.parse().unwrap();
            let mut next = -1e9;
            print!("{:<13}", t.name());
            for x in &r.work[k].samples {
                if x.along_m >= next && x.along_m < 25.0 {
                    print!(" {:.2}", x.xte_m * 100.0);
                    next = x.along_m + 1.0;
                }
            }
            println!();
            continue;
        }
        let mut s = vec![(0.0f64, 0usize, 0.0f64); bins.len()];
        let (mut tot, mut n) = (0.0, 0);
        for p in &r.work {
            for x in &p.samples {
                if x.along_m < 10.0 {
                    continue;
                }
                let i = bins
                    .iter()
                    .position(|b| x.along_m < *b)
                    .unwrap_or(bins.len() - 1);
                s[i].0 += x.xte_m * x.xte_m;
                s[i].1 += 1;
                s[i].2 = s[i].2.max(x.xte_m.abs());
                tot += x.xte_m * x.xte_m;
                n += 1;
            }
        }
        print!(
            "{:<13} rms {:.3} |",
            t.name(),
            (tot / n as f64).sqrt() * 100.0
        );
        for (i, b) in s.iter().enumerate() {
            print!(
                " <{:>4}: {:.3}/{:.2} ({:4.1}%)",
                bins[i].min(999.0),
                (b.0 / b.1.max(1) as f64).sqrt() * 100.0,
                b.2 * 100.0,
                100.0 * b.0 / tot
            );
        }
        println!();
    }
}
