//! The whole protocol from the library, without the `evtac` binary: simulate every protocol at a
//! scale, then run `pipeline::reproduce` and print the stage times.
//!
//! `cargo run -p evtac-experiments --example reproduce -- small OUT_DIR [SEED]`

use evtac_experiments::jobs;
use evtac_experiments::pipeline::{Datasets, reproduce};
use evtac_experiments::plan::Plan;
use evtac_experiments::progress::Quiet;
use evtac_sim::{DatasetConfig, Protocol, Scale, simulate_dataset};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let scale_name = args.next().unwrap_or_else(|| "tiny".into());
    let out = PathBuf::from(args.next().unwrap_or_else(|| "reproduce-out".into()));
    let seed: u64 = args.next().map_or(Ok(0), |s| s.parse())?;
    let scale: Scale = scale_name.parse()?;
    let plan = Plan::for_scale(scale);
    let started = Instant::now();
    let data = out.join("data");
    for protocol in [
        Protocol::Exp1,
        Protocol::Exp2,
        Protocol::Exp3Speed,
        Protocol::Exp3Depth,
    ] {
        let dir = data.join(protocol.name());
        if !jobs::is_done(&dir) {
            simulate_dataset(&DatasetConfig::new(protocol, scale, seed), &dir, |_| {})?;
            jobs::mark_done(&dir)?;
        }
    }
    eprintln!("simulated in {:.1} s", started.elapsed().as_secs_f64());
    let log = evtac_experiments::stage_log::StageLog::open(&out)?;
    let results = reproduce(&Datasets::in_dir(&data), &plan, seed, &out, &log, &Quiet)?;
    for (stage, s) in &results.run.stage_seconds {
        eprintln!("{stage}: {s:.1} s");
    }
    for e in &results.exp1 {
        eprintln!("{}: test MAE {}", e.name, e.test.overall.display());
    }
    eprintln!("total {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}
