//! The zero-phase Butterworth low-pass that smooths the axial angular velocity before it is
//! integrated.
//!
//! Design and filtering come from [`sci_rs`], which follows SciPy: [`LowPass::new`] is
//! `scipy.signal.butter(order, cutoff_hz, fs=fs_hz, output='sos')` and [`LowPass::filtfilt`] is
//! `scipy.signal.sosfiltfilt(sos, x)`. For a Butterworth low-pass that is, up to rounding (the
//! second-order sections are the better-conditioned form), `scipy.signal.filtfilt(b, a, x)` with
//! its default edge handling: odd extension by `padlen = 3 * max(len(a), len(b)) = 3 * (order +
//! 1)` samples at both ends and steady-state initial conditions scaled by the first sample of each
//! pass. The tests pin both against SciPy's numbers.
//!
//! sci-rs panics on arguments SciPy rejects (cutoff outside `(0, fs/2)`, too short a signal);
//! this module checks them first and returns a [`FilterError`] instead.

use sci_rs::signal::filter::design::{
    DigitalFilter, FilterBandType, FilterOutputType, Sos, butter_dyn,
};
use sci_rs::signal::filter::sosfiltfilt_dyn;

/// What can go wrong designing or applying the low-pass.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FilterError {
    /// The order must be from 1 to [`LowPass::MAX_ORDER`].
    #[error("filter order {order} is outside 1..={max}", max = LowPass::MAX_ORDER)]
    Order {
        /// The order asked for.
        order: usize,
    },
    /// The cutoff must lie strictly between 0 and the Nyquist frequency.
    #[error(
        "cutoff {cutoff_hz} Hz must lie strictly between 0 and the Nyquist frequency \
         {nyquist_hz} Hz (sampling rate {fs_hz} Hz)"
    )]
    Cutoff {
        /// The cutoff asked for, in Hz.
        cutoff_hz: f64,
        /// Half the sampling rate, in Hz.
        nyquist_hz: f64,
        /// The sampling rate, in Hz.
        fs_hz: f64,
    },
    /// The signal must be longer than the edge padding (SciPy raises the same).
    #[error(
        "signal of {len} samples is too short to filter: it must be longer than the edge \
         padding of {padlen} samples"
    )]
    TooShort {
        /// Number of samples given.
        len: usize,
        /// The padding length, `3 * (order + 1)`.
        padlen: usize,
    },
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite ({value})")]
    NonFinite {
        /// Index of the first such sample.
        index: usize,
        /// Its value.
        value: f64,
    },
}

/// A digital Butterworth low-pass in second-order sections, applied forward and backward.
#[derive(Debug, Clone)]
pub struct LowPass {
    order: usize,
    cutoff_hz: f64,
    fs_hz: f64,
    sos: Vec<Sos<f64>>,
}

impl LowPass {
    /// The highest order accepted. Zero-phase filtering doubles the order; beyond this the
    /// sections gain nothing for labels and lose conditioning.
    pub const MAX_ORDER: usize = 12;

    /// Designs the `order`-th order Butterworth low-pass with -3 dB at `cutoff_hz` for samples
    /// taken at `fs_hz`, as `scipy.signal.butter(order, cutoff_hz, fs=fs_hz, output='sos')`.
    pub fn new(order: usize, cutoff_hz: f64, fs_hz: f64) -> Result<Self, FilterError> {
        if order == 0 || order > Self::MAX_ORDER {
            return Err(FilterError::Order { order });
        }
        let nyquist_hz = fs_hz / 2.0;
        // Written so that NaN fails too.
        if !(cutoff_hz > 0.0 && cutoff_hz < nyquist_hz && fs_hz.is_finite()) {
            return Err(FilterError::Cutoff {
                cutoff_hz,
                nyquist_hz,
                fs_hz,
            });
        }
        let design = butter_dyn(
            order,
            vec![cutoff_hz],
            Some(FilterBandType::Lowpass),
            Some(false),
            Some(FilterOutputType::Sos),
            Some(fs_hz),
        );
        let DigitalFilter::Sos(sos) = design else {
            unreachable!("butter_dyn returns the representation it is asked for")
        };
        Ok(Self {
            order,
            cutoff_hz,
            fs_hz,
            sos: sos.sos,
        })
    }

    /// The filter order (of one pass).
    pub fn order(&self) -> usize {
        self.order
    }

    /// The -3 dB frequency of one pass, in Hz (the zero-phase result is -6 dB there).
    pub fn cutoff_hz(&self) -> f64 {
        self.cutoff_hz
    }

    /// The sampling rate the filter was designed for, in Hz.
    pub fn fs_hz(&self) -> f64 {
        self.fs_hz
    }

    /// The second-order sections as SciPy lays them out: one row `[b0, b1, b2, a0, a1, a2]` per
    /// section.
    pub fn sos(&self) -> Vec<[f64; 6]> {
        self.sos
            .iter()
            .map(|s| [s.b[0], s.b[1], s.b[2], s.a[0], s.a[1], s.a[2]])
            .collect()
    }

    /// The transfer function `(b, a)` (`output='ba'` in SciPy), multiplied out from the sections,
    /// each of length `order + 1`.
    pub fn transfer_function(&self) -> (Vec<f64>, Vec<f64>) {
        let mut b = vec![1.0];
        let mut a = vec![1.0];
        for s in &self.sos {
            b = polymul(&b, &s.b);
            a = polymul(&a, &s.a);
        }
        // An odd order leaves a first-order section whose third coefficients are zero.
        b.truncate(self.order + 1);
        a.truncate(self.order + 1);
        (b, a)
    }

    /// The number of samples of odd extension at each end: SciPy's default
    /// `3 * max(len(a), len(b)) = 3 * (order + 1)`.
    pub fn padlen(&self) -> usize {
        3 * (self.order + 1)
    }

    /// Filters `x` forward and backward (zero phase, squared magnitude response), with SciPy's
    /// default odd edge padding. `x` must be finite and longer than [`Self::padlen`].
    pub fn filtfilt(&self, x: &[f64]) -> Result<Vec<f64>, FilterError> {
        if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(FilterError::NonFinite { index, value });
        }
        if x.len() <= self.padlen() {
            return Err(FilterError::TooShort {
                len: x.len(),
                padlen: self.padlen(),
            });
        }
        Ok(sosfiltfilt_dyn(x.iter(), &self.sos))
    }
}

/// The product of two polynomials given by their coefficients.
fn polymul(p: &[f64], q: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; p.len() + q.len() - 1];
    for (i, pi) in p.iter().enumerate() {
        for (j, qj) in q.iter().enumerate() {
            out[i + j] += pi * qj;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    //! Reference values from SciPy 1.17.1 (numpy 2.4.6), printed by this script:
    //!
    //! ```python
    //! import numpy as np
    //! from scipy import signal
    //! n = 600
    //! i = np.arange(n)
    //! cases = [(4, 20.0, 800.0), (3, 35.0, 805.0), (2, 5.0, 250.0)]
    //! for order, fc, fs in cases:
    //!     t = i / fs
    //!     x = np.sin(2*np.pi*3*t) + 0.5*np.sin(2*np.pi*70*t) + (i >= 300) + 0.01*i
    //!     b, a = signal.butter(order, fc, fs=fs)
    //!     sos = signal.butter(order, fc, fs=fs, output='sos')
    //!     y = signal.filtfilt(b, a, x)  # padtype='odd', padlen=3*max(len(a), len(b))
    //!     ys = signal.sosfiltfilt(sos, x)
    //!     print(f"case order={order} fc={fc} fs={fs} "
    //!           f"max|filtfilt-sosfiltfilt|={np.max(np.abs(y-ys)):.2e}")
    //!     print("b =", ", ".join(repr(float(v)) for v in b))
    //!     print("a =", ", ".join(repr(float(v)) for v in a))
    //!     print("sos =", ", ".join(repr(float(v)) for v in sos.ravel()))
    //!     idx = [0, 1, 2, 7, 50, 150, 299, 300, 301, 450, 597, 598, 599]
    //!     print("y =", ", ".join(f"({k}, {float(y[k])!r})" for k in idx))
    //! ```
    //!
    //! SciPy's own `filtfilt` and `sosfiltfilt` differ by up to 1.5e-11 on these inputs (the
    //! transfer-function form rounds worse), so outputs are compared at 1e-9.

    use super::*;

    struct Case {
        order: usize,
        fc: f64,
        fs: f64,
        b: &'static [f64],
        a: &'static [f64],
        sos: &'static [f64],
        y: &'static [(usize, f64)],
    }

    const CASES: [Case; 3] = [
        Case {
            order: 4,
            fc: 20.0,
            fs: 800.0,
            b: &[
                3.123897691708262e-05,
                0.00012495590766833047,
                0.0001874338615024957,
                0.00012495590766833047,
                3.123897691708262e-05,
            ],
            a: &[
                1.0,
                -3.5897338871121756,
                4.851275882519417,
                -2.9240526561624587,
                0.663010484385891,
            ],
            sos: &[
                3.123897691708262e-05,
                6.247795383416523e-05,
                3.123897691708262e-05,
                1.0,
                -1.7259333950369407,
                0.7474473719077911,
                1.0,
                2.0,
                1.0,
                1.0,
                -1.863800492075235,
                0.8870329996526946,
            ],
            y: &[
                (0, 0.000850160692329417),
                (1, 0.041591762199974375),
                (2, 0.08114302566384556),
                (7, 0.26197008243626374),
                (50, 1.426078365739108),
                (150, 1.117299049950872),
                (299, 4.15462511013795),
                (300, 4.232766620167242),
                (301, 4.3102495536864645),
                (450, 4.576161900702883),
                (597, 8.070015643027947),
                (598, 8.083724069027594),
                (599, 8.095844446539614),
            ],
        },
        Case {
            order: 3,
            fc: 35.0,
            fs: 805.0,
            b: &[
                0.001974186432442846,
                0.005922559297328538,
                0.005922559297328538,
                0.001974186432442846,
            ],
            a: &[
                1.0,
                -2.4552464101944036,
                2.0490892415200825,
                -0.5780493398661363,
            ],
            sos: &[
                0.001974186432442846,
                0.003948372864885692,
                0.001974186432442846,
                1.0,
                -0.7583239375151349,
                0.0,
                1.0,
                1.0,
                0.0,
                1.0,
                -1.6969224726792684,
                0.7622723103800206,
            ],
            y: &[
                (0, -0.0024818339214562),
                (1, 0.03281255972070288),
                (2, 0.06778883552361196),
                (7, 0.22548417431798815),
                (50, 1.426671787012275),
                (150, 1.1395424334885553),
                (299, 4.102542342066333),
                (300, 4.224356812909689),
                (301, 4.343131077432822),
                (450, 4.608329761387952),
                (597, 8.114012559310629),
                (598, 8.182843953171224),
                (599, 8.253778120821046),
            ],
        },
        Case {
            order: 2,
            fc: 5.0,
            fs: 250.0,
            b: &[
                0.0036216815149286417,
                0.007243363029857283,
                0.0036216815149286417,
            ],
            a: &[1.0, -1.822694925196308, 0.8371816512560226],
            sos: &[
                0.0036216815149286417,
                0.007243363029857283,
                0.0036216815149286417,
                1.0,
                -1.822694925196308,
                0.8371816512560226,
            ],
            y: &[
                (0, 0.05656512061072481),
                (1, 0.12187431712743733),
                (2, 0.1879985569755988),
                (7, 0.5160551162062929),
                (50, -0.019826123174638416),
                (150, 0.6577342256877853),
                (299, 3.00273269053821),
                (300, 3.0016138906672616),
                (301, 3.00314500075846),
                (450, 6.020547997926853),
                (597, 7.356847147375765),
                (598, 7.369922448734786),
                (599, 7.379790868718894),
            ],
        },
    ];

    fn input(fs: f64) -> Vec<f64> {
        use std::f64::consts::PI;
        (0..600)
            .map(|i| {
                let t = i as f64 / fs;
                (2.0 * PI * 3.0 * t).sin()
                    + 0.5 * (2.0 * PI * 70.0 * t).sin()
                    + if i >= 300 { 1.0 } else { 0.0 }
                    + 0.01 * i as f64
            })
            .collect()
    }

    fn assert_close(got: &[f64], want: &[f64], tol: f64, what: &str) {
        assert_eq!(got.len(), want.len(), "{what}: lengths differ");
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(
                (g - w).abs() <= tol * w.abs().max(1.0),
                "{what}[{k}]: got {g}, SciPy {w}"
            );
        }
    }

    #[test]
    fn butter_matches_scipy() {
        for c in &CASES {
            let f = LowPass::new(c.order, c.fc, c.fs).unwrap();
            let what = format!("order {} fc {} fs {}", c.order, c.fc, c.fs);
            let sos: Vec<f64> = f.sos().into_iter().flatten().collect();
            assert_close(&sos, c.sos, 1e-12, &format!("{what} sos"));
            let (b, a) = f.transfer_function();
            assert_close(&b, c.b, 1e-12, &format!("{what} b"));
            assert_close(&a, c.a, 1e-12, &format!("{what} a"));
            assert_eq!(f.padlen(), 3 * c.a.len().max(c.b.len()));
        }
    }

    #[test]
    fn filtfilt_matches_scipy() {
        for c in &CASES {
            let f = LowPass::new(c.order, c.fc, c.fs).unwrap();
            let y = f.filtfilt(&input(c.fs)).unwrap();
            assert_eq!(y.len(), 600);
            let got: Vec<f64> = c.y.iter().map(|&(k, _)| y[k]).collect();
            let want: Vec<f64> = c.y.iter().map(|&(_, v)| v).collect();
            let what = format!("filtfilt order {} fc {} fs {}", c.order, c.fc, c.fs);
            assert_close(&got, &want, 1e-9, &what);
        }
    }

    #[test]
    fn filtfilt_keeps_constants() {
        // Steady-state initial conditions pass a constant through without an edge transient.
        let f = LowPass::new(4, 20.0, 800.0).unwrap();
        let x = vec![-0.37; 200];
        let y = f.filtfilt(&x).unwrap();
        for (a, b) in x.iter().zip(&y) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn rejects_what_scipy_rejects() {
        assert_eq!(
            LowPass::new(0, 20.0, 800.0).unwrap_err(),
            FilterError::Order { order: 0 }
        );
        assert!(matches!(
            LowPass::new(4, 400.0, 800.0),
            Err(FilterError::Cutoff { .. })
        ));
        assert!(matches!(
            LowPass::new(4, f64::NAN, 800.0),
            Err(FilterError::Cutoff { .. })
        ));
        let f = LowPass::new(4, 20.0, 800.0).unwrap();
        assert_eq!(
            f.filtfilt(&[0.0; 15]).unwrap_err(),
            FilterError::TooShort {
                len: 15,
                padlen: 15
            }
        );
        assert!(f.filtfilt(&[0.0; 16]).is_ok());
        let mut x = vec![0.0; 40];
        x[7] = f64::NAN;
        assert!(matches!(
            f.filtfilt(&x),
            Err(FilterError::NonFinite { index: 7, .. })
        ));
        let err = LowPass::new(4, 500.0, 800.0).unwrap_err().to_string();
        assert!(err.contains("500 Hz") && err.contains("400 Hz"), "{err}");
    }
}
