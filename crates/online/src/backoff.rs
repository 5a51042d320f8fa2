//! Reconnection policy for network inputs: exponential backoff with a bounded number of attempts.

use std::time::Duration;

/// How a dropped or stalled network input is retried.
///
/// Attempt `n` (0-based) waits `min(initial * 2^n, max)` before connecting; after `attempts`
/// failed attempts in a row the input ends (estimates for every event that did arrive are still
/// emitted). A connection that delivers data resets the count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Backoff {
    /// Wait before the first reconnection attempt.
    pub initial: Duration,
    /// Longest wait between attempts.
    pub max: Duration,
    /// Reconnection attempts in a row before giving up (0: end at the first drop).
    pub attempts: u32,
}

impl Default for Backoff {
    /// 100 ms, doubling up to 5 s, 8 attempts (about 17 s in all before giving up).
    fn default() -> Self {
        Self {
            initial: Duration::from_millis(100),
            max: Duration::from_secs(5),
            attempts: 8,
        }
    }
}

impl Backoff {
    /// The wait before attempt `n` (0-based), or `None` once `attempts` are used up.
    pub fn delay(&self, n: u32) -> Option<Duration> {
        if n >= self.attempts {
            return None;
        }
        // 2^n saturates long before u32 overflows matter: cap the shift, then the product.
        let factor = 1u32.checked_shl(n.min(31)).unwrap_or(u32::MAX);
        Some(self.initial.saturating_mul(factor).min(self.max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubles_caps_and_stops() {
        let b = Backoff {
            initial: Duration::from_millis(100),
            max: Duration::from_millis(500),
            attempts: 5,
        };
        let delays: Vec<_> = (0..6).map(|n| b.delay(n)).collect();
        let ms = |v| Some(Duration::from_millis(v));
        assert_eq!(
            delays,
            vec![ms(100), ms(200), ms(400), ms(500), ms(500), None]
        );
    }

    #[test]
    fn zero_attempts_never_retries_and_huge_counts_saturate() {
        let b = Backoff {
            attempts: 0,
            ..Backoff::default()
        };
        assert_eq!(b.delay(0), None);
        let b = Backoff {
            attempts: u32::MAX,
            ..Backoff::default()
        };
        assert_eq!(b.delay(40), Some(b.max));
    }
}
