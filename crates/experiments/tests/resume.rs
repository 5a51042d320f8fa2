//! Interrupted runs resume from finished jobs.

use crate::simulate;
use evtac_experiments::cache::FeatureCache;
use evtac_experiments::dataset::Dataset;
use evtac_experiments::exp1;
use evtac_experiments::job::{Job, TrainJob};
use evtac_experiments::jobs;
use evtac_experiments::plan::{self, Plan};
use evtac_experiments::progress::Quiet;
use evtac_import::inputs::Inputs;
use evtac_learn::ModelBundle;
use evtac_sim::Protocol;
use std::path::Path;

#[test]
fn resumed_run_redoes_only_the_unfinished_job() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("exp1");
    let out = dir.path().join("out");
    simulate(&data, Protocol::Exp1, 6);
    let ds = Dataset::open(&data, Inputs::FROM_FILES).unwrap();
    let splits = ds.splits(1).unwrap();
    assert!(data.join("splits.json").is_file());
    let cache = FeatureCache::new(&ds).unwrap();
    let mut p = Plan::for_scale(evtac_sim::Scale::Tiny);
    p.epochs = 1;
    p.seeds = 2;
    let reprs = exp1::representations(
        plan::static_config(1000.0, 2.0),
        plan::dynamic_config(640.0, 0),
    );
    let list = exp1::jobs(&ds, &reprs[..1], &p, 5, &out);
    assert_eq!(list.len(), 2);
    exp1::train_all(&cache, &splits, &list, &Quiet).unwrap();
    assert!(list.iter().all(|j| jobs::is_done(&j.out)));
    let weights = |j: &TrainJob| std::fs::read(j.out.join("model.safetensors")).unwrap();
    let before: Vec<Vec<u8>> = list.iter().map(weights).collect();
    // "Interrupt" the second job: its marker and weights are gone, a stale file is left.
    std::fs::remove_file(list[1].out.join(jobs::DONE)).unwrap();
    std::fs::write(list[1].out.join("model.safetensors"), b"partial").unwrap();
    let stamp = std::fs::metadata(list[0].out.join("model.safetensors"))
        .unwrap()
        .modified()
        .unwrap();
    exp1::train_all(&cache, &splits, &list, &Quiet).unwrap();
    // The finished job was not touched; the unfinished one was redone, to the same bytes.
    let stamp_after = std::fs::metadata(list[0].out.join("model.safetensors"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(stamp, stamp_after);
    assert!(jobs::is_done(&list[1].out));
    assert_eq!(weights(&list[1]), before[1]);
    assert!(ModelBundle::load(&list[1].out).is_ok());

    // The same job run on its own, as `evtac jobs run` runs it from a jobs file (opening the
    // dataset itself): the same bytes as the local pipeline's run.
    let alone = TrainJob {
        out: dir.path().join("alone"),
        ..list[0].clone()
    };
    let text = evtac_experiments::job::to_text(&[Job::Train(alone.clone())]);
    let [Job::Train(read)] =
        &evtac_experiments::job::parse(Path::new("x.jobs"), &text).unwrap()[..]
    else {
        panic!("one train job");
    };
    evtac_experiments::training::run_job(read, &|_| {}, |_| {}).unwrap();
    assert_eq!(weights(&alone), before[0]);
}
