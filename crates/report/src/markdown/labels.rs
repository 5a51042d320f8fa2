//! The report's label-validation section: Experiment 2's labels against the commanded stop
//! angles (the paper's own check) and the simulator's ground truth, beside the paper's number.

use evtac_experiments::results::LabelCheck;
use evtac_labels::LabelSource;

/// The paper's label validation at the stops: mean and standard deviation, degrees.
pub const PAPER_STOP_ERROR_DEG: (f64, f64) = (-0.01, 0.04);

/// The report's section on the labels: the stop check beside the paper's, and the error against
/// the ground truth when there is one.
pub fn section(check: Option<&LabelCheck>) -> String {
    let mut md = String::from("## Labels\n\n");
    let Some(check) = check else {
        md.push_str(
            "Not checked: no Experiment 2 dataset (its stops are what the check uses).\n\n",
        );
        return md;
    };
    let (mean, sd) = PAPER_STOP_ERROR_DEG;
    if check.label_source == LabelSource::Commanded {
        md.push_str(
            "The labels are the robot's commanded motion (`label_source.json`: the recordings \
             hold no IMU), not the paper's IMU labels: they leave out how the robot tracked its \
             command, and the paper's stop check, which would compare the command with itself, \
             is not made.",
        );
    }
    match &check.stop_error_deg {
        _ if check.label_source == LabelSource::Commanded => {}
        Some(s) => md.push_str(&format!(
            "Mean labelled tilt over each stop of Experiment 2 minus the robot's commanded stop \
             angle: {:+.3} ± {:.3} deg over {} stops (range {:+.3} .. {:+.3}); the paper: \
             {mean:+.2} ± {sd:.2} deg.",
            s.mean, s.std, s.n, s.min, s.max
        )),
        None => md.push_str("No trial of Experiment 2 has a stop to check the labels against."),
    }
    if let Some(r) = &check.truth_rms_deg {
        md.push_str(&format!(
            " Against the simulator's exact ground truth (the pose in the sensor's frame), the \
             labels' RMS error over pitch and roll is {:.3} deg per trial on average (at most \
             {:.3}, {} trials); it includes the turn of the sensor's seating, which labels on \
             the commanded rolling axis do not see (`rig.reseat_rotation_sd_deg`). On simulated \
             data the stop check measures the labels' own error together with the robot's \
             repeatability, which the simulator takes from the ABB IRB 120's specification \
             (`rig.angle_sd_deg` in `docs/simulator.md`), not tuned to the paper's spread: a \
             tighter or wider spread than the paper's is a finding about the simulated rig.",
            r.mean, r.max, r.n
        ));
    }
    if let Some(r) = &check.truth_stop_rms_deg {
        md.push_str(&format!(
            " Over each stop (inside the stop check's margins), the labels' RMS error against \
             the truth is {:.3} deg per trial on average (at most {:.3}, {} trials): their own \
             error where the paper checks them, without the robot's repeatability.",
            r.mean, r.max, r.n
        ));
    }
    md.push_str("\n\n");
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use evtac_labels::Summary;

    #[test]
    fn the_section_puts_the_stop_check_beside_the_paper_s() {
        let check = LabelCheck {
            stop_error_deg: Summary::of(&[-0.05, 0.01, 0.02]),
            truth_rms_deg: Summary::of(&[0.01, 0.03]),
            label_source: LabelSource::Imu,
            truth_stop_rms_deg: Summary::of(&[0.002, 0.004]),
        };
        let md = section(Some(&check));
        assert!(md.contains("-0.007 ± 0.038 deg over 3 stops"), "{md}");
        assert!(md.contains("the paper: -0.01 ± 0.04 deg"), "{md}");
        assert!(
            md.contains("0.020 deg per trial on average (at most 0.030, 2 trials)"),
            "{md}"
        );
        assert!(
            md.contains("against the truth is 0.003 deg per trial on average (at most 0.004, 2"),
            "{md}"
        );
        assert!(section(None).contains("Not checked"));
    }

    #[test]
    fn labels_from_the_command_are_named_and_not_checked_against_it() {
        let check = LabelCheck {
            stop_error_deg: None,
            truth_rms_deg: None,
            label_source: LabelSource::Commanded,
            truth_stop_rms_deg: None,
        };
        let md = section(Some(&check));
        assert!(md.contains("the robot's commanded motion"), "{md}");
        assert!(md.contains("is not made"), "{md}");
        assert!(!md.contains("No trial of Experiment 2"), "{md}");
    }
}
