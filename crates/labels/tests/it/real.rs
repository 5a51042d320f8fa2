//! A real DVXplorer IMU stream (`dvxplorer_320x240_imu.aedat4`, the sensor at rest) passes the
//! stream checks, and its noise is what the synthetic gyroscope assumes.

use evtac_labels::bias::stationary_bias;
use evtac_labels::dataset::read_imu;
use evtac_labels::geometry::Calibration;
use evtac_labels::rate::AxialRate;

#[test]
fn a_real_imu_stream_passes_the_checks() {
    let Some(path) = evtac_testkit::real_fixture("dvxplorer_320x240_imu.aedat4") else {
        return;
    };
    let imu = read_imu(&path).unwrap();
    assert_eq!(imu.len(), 475);
    for phi in [0.0, 90.0] {
        let rate = AxialRate::from_imu(&imu, &Calibration::default(), phi, 5.0).unwrap();
        // Figures from EXPECTED.md: about 805 Hz.
        assert_eq!(rate.median_interval_us, 1242);
        let end = rate.t_us[rate.t_us.len() - 1] + 1;
        let bias = stationary_bias(&rate.t_us, &rate.rate_deg_s, end, 100_000, 20).unwrap();
        assert_eq!(bias.samples, 475);
        // The synthetic gyroscope of the other tests uses 0.12 deg/s of white noise.
        assert!(
            (0.1..0.16).contains(&bias.noise_deg_s),
            "phi {phi}: {bias:?}"
        );
    }
}
