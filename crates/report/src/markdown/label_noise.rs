//! The report's label-noise ablation section: Experiment 1's paper representations trained on
//! labels with Gaussian noise added, beside the same trained on the clean labels.

use evtac_experiments::results::LabelNoise;

/// The section, or a line saying it was not run.
pub fn section(ablation: Option<&LabelNoise>) -> String {
    let mut md = String::from("## Label-noise ablation (test MAE, degrees)\n\n");
    let Some(a) = ablation else {
        md.push_str(
            "Not run: the plan has no label-noise ablation (`--label-noise-deg 0`, or results \
             from before it existed).\n\n",
        );
        return md;
    };
    md.push_str(&format!(
        "Experiment 1's representations trained again with Gaussian noise of {} deg standard \
         deviation added to every training label, pitch and roll (the spread of the paper's \
         label check at stops: -0.01 ± 0.04 deg), with the same settings, seeds and initial \
         weights; tested on the same clean test labels. The simulator's own labels are nearly \
         exact, so this says what labels as noisy as the paper's would cost here. The change is \
         the mean over seeds of each seed's noisy-minus-clean test MAE, ± its standard \
         deviation.\n\n| representation | clean labels | noisy labels | change |\n| --- | ---: | \
         ---: | ---: |\n",
        a.sd_deg
    ));
    super::paired::rows(&mut md, &a.clean, &a.noisy);
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_experiments::results::Exp1Repr;
    use evtac_repr::ReprKind;

    fn repr(maes: &[f64]) -> Exp1Repr {
        super::super::repr_of(ReprKind::Static, maes)
    }

    #[test]
    fn the_change_is_paired_by_seed_and_judged_against_the_spread() {
        let a = LabelNoise {
            sd_deg: 0.04,
            clean: vec![repr(&[0.30, 0.20, 0.25])],
            noisy: vec![repr(&[0.31, 0.21, 0.26])],
        };
        let md = section(Some(&a));
        // Each seed is 0.01 worse: the paired change is exact, though the seeds spread by 0.05.
        assert!(md.contains("| +0.010 ± 0.000 |"), "{md}");
        assert!(md.contains("within the seeds' spread of "), "{md}");
        assert!(section(None).contains("Not run"));
    }
}
