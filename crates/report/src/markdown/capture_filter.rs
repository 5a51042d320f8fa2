//! The report's capture-filter ablation section: Experiment 1's paper representations on every
//! recording through the NeuroTac lab's capture filter, beside the same on the unfiltered
//! events, paired by seed ([`super::paired`]).

use evtac_experiments::results::CaptureFilter;

/// The section, or a line saying it was not run.
pub fn section(ablation: Option<&CaptureFilter>) -> String {
    let mut md = String::from("## Capture-filter ablation (test MAE, degrees)\n\n");
    let Some(a) = ablation else {
        md.push_str(
            "Not run: the plan has no capture-filter ablation (`--no-capture-filter`, a scale \
             without one, or results from before it existed).\n\n",
        );
        return md;
    };
    md.push_str(&format!(
        "Experiment 1's representations trained and tested again with every recording of the \
         dataset, its trials and its no-contact recording, through `{}` on the full sensor \
         before the crop (the NeuroTac lab's capture code passes every recording through \
         dv-processing's `BackgroundActivityNoiseFilter` with a 10 ms window before saving it), \
         with the same settings, seeds, initial weights and split. The change is the mean over \
         seeds of each seed's filtered-minus-unfiltered test MAE, ± its standard deviation. On \
         simulated data this is what the filter does to the method on evtac's simulator, whose \
         background noise and hot pixels are the simulator's (`docs/simulator.md`), not a real \
         sensor's.\n\n| representation | unfiltered | filtered | change |\n| --- | ---: | ---: | \
         ---: |\n",
        a.spec
    ));
    super::paired::rows(&mut md, &a.unfiltered, &a.filtered);
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_repr::ReprKind;

    #[test]
    fn the_change_is_paired_by_seed_and_names_the_filter() {
        let repr = |maes: &[f64]| super::super::repr_of(ReprKind::Dynamic, maes);
        let a = CaptureFilter {
            spec: "background-activity=10ms".into(),
            unfiltered: vec![repr(&[0.30, 0.20, 0.25])],
            filtered: vec![repr(&[0.25, 0.15, 0.20])],
        };
        let md = section(Some(&a));
        assert!(md.contains("through `background-activity=10ms`"), "{md}");
        assert!(
            md.contains("| Dynamic | 0.250 ± 0.050 | 0.200 ± 0.050 | -0.050 ± 0.000 |"),
            "{md}"
        );
        assert!(
            md.contains("Dynamic changes by -0.050 deg, within "),
            "{md}"
        );
        assert!(section(None).contains("Not run"));
    }
}
