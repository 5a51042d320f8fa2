//! The latency section's "End to end, queueing included" part: a few test trials replayed at
//! the recorded pace through `evtac online`'s pipeline, idle and under load
//! (`evtac_experiments::paced_latency`), beside the processing times above it. What the replay
//! was (trials, seconds, load, cores) is read from the cells, so the text says what was run.

use std::fmt::Write as _;

use evtac_experiments::paced_latency::{Load, PacedLatencyCell};
use evtac_experiments::results::Results;

/// The sub-section; "Not measured" for results from before the replay was part of the run.
pub(super) fn section(md: &mut String, r: &Results) {
    let _ = writeln!(
        md,
        "### End to end, queueing included (replay at the recorded pace, microseconds)\n"
    );
    let cells = &r.paced_latency;
    let Some(first) = cells.first() else {
        let _ = writeln!(
            md,
            "Not measured: these results are from before the replay at recorded pace was part \
             of the run.\n"
        );
        return;
    };
    let trials = first.trials;
    let seconds = cells.iter().map(|c| c.replayed_s).fold(0.0, f64::max);
    let cores = match first.cores {
        0 => "this machine".to_string(),
        n => format!("this machine's {n} logical cores"),
    };
    let _ = writeln!(
        md,
        "{trials} test trial{} of those above (the fastest-moving: the busiest event streams), \
         {seconds:.1} s of motion in all, replayed on the wall clock through the pipeline \
         `evtac online --realtime` runs, once per representation, interval and load: each \
         interval's events are released to the estimator when the clock reaches their recorded \
         time, and the estimator takes them as they come, so a step that takes longer than the \
         interval makes the later ones wait. Each figure runs from the instant a step's events \
         were due to the end of its estimate's forward pass, so the processing, the wait in the \
         queue behind earlier steps and the waking of the threads all count. Transmission from \
         the sensor to the host (and decoding its packets) is still excluded: the events come \
         from memory. *Idle*: nothing else started; *one busy thread*: one more thread spinning \
         on floating-point multiplies and adds, started before each replay and stopped after \
         it, beside the replay's ingestion, estimation and consumer threads on {cores}.\n",
        if trials == 1 { "" } else { "s" },
    );
    let _ = writeln!(
        md,
        "| representation | interval (ms) | load | samples | median | P99 | max | over interval (%) |\n\
         | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: |"
    );
    for c in cells {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.0} | {:.0} | {:.0} | {:.1} |",
            c.name,
            c.interval_ms,
            c.load.name(),
            c.samples,
            c.median_us,
            c.p99_us,
            c.max_us,
            c.late_share * 100.0
        );
    }
    let sentences: Vec<String> = Load::ALL
        .into_iter()
        .filter_map(|load| worst(cells, load))
        .collect();
    if sentences.is_empty() {
        let _ = writeln!(md);
    } else {
        let _ = writeln!(md, "\n{}.\n", sentences.join("; "));
    }
}

/// What the cells of `load` say at worst: the highest P99 and the largest late share, with
/// where they were; `None` when `load` was not measured.
fn worst(cells: &[PacedLatencyCell], load: Load) -> Option<String> {
    let of_load: Vec<&PacedLatencyCell> = cells.iter().filter(|c| c.load == load).collect();
    let p99 = of_load
        .iter()
        .max_by(|a, b| a.p99_us.total_cmp(&b.p99_us))?;
    let late = of_load
        .iter()
        .max_by(|a, b| a.late_share.total_cmp(&b.late_share))?;
    let lateness = if late.late_share > 0.0 {
        format!(
            "at most {:.1} % of estimates over the interval ({} at {} ms)",
            late.late_share * 100.0,
            late.name,
            late.interval_ms
        )
    } else {
        "no estimate over the interval".to_string()
    };
    let load = match load {
        Load::Idle => "Idle".to_string(),
        other => format!("with {}", other.name()),
    };
    Some(format!(
        "{load}, the highest P99 is {:.0} us ({} at {} ms), {lateness}",
        p99.p99_us, p99.name, p99.interval_ms
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_repr::ReprKind;

    fn example() -> Results {
        serde_json::from_str(include_str!("../../../../docs/report-example/results.json"))
            .expect("the example report's results")
    }

    fn cell(
        name: ReprKind,
        interval_ms: u32,
        load: Load,
        p99_us: f64,
        late: f64,
    ) -> PacedLatencyCell {
        PacedLatencyCell {
            name,
            interval_ms,
            load,
            trials: 2,
            replayed_s: 4.0,
            cores: 2,
            samples: 4000,
            median_us: 60.0,
            p99_us,
            max_us: 3000.0,
            late_share: late,
        }
    }

    #[test]
    fn older_results_say_not_measured() {
        let mut older = example();
        older.paced_latency.clear();
        let mut md = String::new();
        section(&mut md, &older);
        assert!(md.starts_with("### End to end, queueing included"), "{md}");
        assert!(md.contains("Not measured"), "{md}");
        assert!(!md.contains('|'), "{md}");
    }

    #[test]
    fn the_table_and_the_worst_cases_come_from_the_cells() {
        let mut r = example();
        r.paced_latency = vec![
            cell(ReprKind::Static, 1, Load::Idle, 120.0, 0.0),
            cell(ReprKind::Combined, 1, Load::Idle, 180.0, 0.0),
            cell(ReprKind::Static, 1, Load::BusyThread, 900.0, 0.0005),
            cell(ReprKind::Combined, 10, Load::BusyThread, 2500.0, 0.02),
        ];
        let mut md = String::new();
        section(&mut md, &r);
        assert!(
            md.contains("2 test trials of those above (the fastest-moving"),
            "{md}"
        );
        assert!(md.contains("4.0 s of motion"), "{md}");
        assert!(md.contains("this machine's 2 logical cores"), "{md}");
        assert!(md.contains("still excluded"), "{md}");
        assert!(
            md.contains("| Combined | 10 | one busy thread | 4000 | 60 | 2500 | 3000 | 2.0 |"),
            "{md}"
        );
        assert!(
            md.contains(
                "Idle, the highest P99 is 180 us (Combined at 1 ms), no estimate over the interval"
            ),
            "{md}"
        );
        assert!(
            md.contains(
                "with one busy thread, the highest P99 is 2500 us (Combined at 10 ms), at most \
                 2.0 % of estimates over the interval (Combined at 10 ms)."
            ),
            "{md}"
        );
        // Idle alone: no sentence about a load that was not run.
        r.paced_latency.truncate(2);
        let mut md = String::new();
        section(&mut md, &r);
        assert!(!md.contains("busy thread, the highest"), "{md}");
    }
}
