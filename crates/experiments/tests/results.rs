//! `results.json` is typed data: the committed example report's file (written before the fields
//! were typed, its configs and plan then `serde_json::Value`s) still reads, every field in its
//! type, and a typed round trip loses nothing.

use evtac_experiments::results::Results;
use evtac_repr::ReprKind;

#[test]
fn the_committed_example_results_read_as_typed_data() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/report-example/results.json"
    );
    let text = std::fs::read_to_string(path).expect("the example report is committed");
    let r: Results = serde_json::from_str(&text).expect("typed results read the older file");
    let kinds: Vec<ReprKind> = r.exp1.iter().map(|e| e.name).collect();
    assert_eq!(kinds, ReprKind::BINARY);
    for e in &r.exp1 {
        assert_eq!(e.config.kind(), e.name, "{}", e.name);
    }
    let tuned: Vec<ReprKind> = r.tuning.iter().map(|t| t.repr).collect();
    assert_eq!(tuned, [ReprKind::Static, ReprKind::Dynamic]);
    assert_eq!(r.tuning[0].chosen_config, r.exp1[0].config);
    assert_eq!(r.run.plan.scale, r.run.scale);
    assert!(r.run.plan.seeds > 0 && !r.run.plan.static_taus_ms.is_empty());

    let again: Results =
        serde_json::from_str(&serde_json::to_string(&r).expect("writes")).expect("reads back");
    assert_eq!(again, r);
    // Kinds keep the spellings the file always had: titles for representations, the CLI's
    // names for the tuned parts.
    let value = serde_json::to_value(&r).expect("writes");
    assert_eq!(value["exp1"][0]["name"], "Static");
    assert_eq!(value["tuning"][1]["repr"], "dynamic");
}
