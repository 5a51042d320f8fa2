//! Durations in SPECs: a positive whole number of microseconds, written with a unit (`500us`,
//! `2ms`, `1.5ms`, `1s`).
//!
//! A unit is required: a bare `2` could mean 2 us or 2 ms, and a filter set 1000 times too
//! short or too long removes everything or nothing without saying so. Decimals are read
//! exactly (no float), so `0.001s` is 1000 us and `0.5us` is refused rather than rounded.

use std::fmt;
use std::str::FromStr;

/// A positive duration in whole microseconds, the unit of event timestamps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Micros(i64);

impl Micros {
    /// `us` microseconds, or `None` unless `us > 0`.
    pub const fn new(us: i64) -> Option<Self> {
        if us > 0 { Some(Self(us)) } else { None }
    }

    /// The duration in microseconds (always positive).
    pub const fn get(self) -> i64 {
        self.0
    }
}

/// Why a duration did not parse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ParseDurationError {
    /// Nothing was given.
    #[error("is empty")]
    Empty,
    /// The number has no unit after it.
    #[error("has no unit (write it with us, ms or s, e.g. 2ms)")]
    NoUnit,
    /// The unit is none of `us`, `ms`, `s`.
    #[error("has an unknown unit (use us, ms or s)")]
    UnknownUnit,
    /// What comes before the unit is not a decimal number.
    #[error("is not a number followed by us, ms or s")]
    NotANumber,
    /// Zero or negative: no filter window can be empty.
    #[error("is not positive")]
    NotPositive,
    /// A fraction of a microsecond, which timestamps cannot resolve.
    #[error("is not a whole number of microseconds")]
    NotWhole,
    /// More microseconds than a 64-bit timestamp holds.
    #[error("is too long (at most 9223372036854775807 us)")]
    TooLong,
}

impl FromStr for Micros {
    type Err = ParseDurationError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim();
        if s.is_empty() {
            return Err(ParseDurationError::Empty);
        }
        let split = s
            .find(|c: char| c.is_alphabetic() || c == 'µ')
            .unwrap_or(s.len());
        let (number, unit) = (s[..split].trim_end(), &s[split..]);
        if number.is_empty() {
            return Err(ParseDurationError::NotANumber);
        }
        let scale_digits = match unit {
            "" => return Err(ParseDurationError::NoUnit),
            "us" | "µs" => 0,
            "ms" => 3,
            "s" => 6,
            _ => return Err(ParseDurationError::UnknownUnit),
        };
        let us = exact_decimal(number, scale_digits)?;
        if us <= 0 {
            return Err(ParseDurationError::NotPositive);
        }
        i64::try_from(us)
            .map(Self)
            .map_err(|_| ParseDurationError::TooLong)
    }
}

/// `number` times `10^scale_digits` as an integer, read digit by digit so no float rounds it.
fn exact_decimal(number: &str, scale_digits: usize) -> Result<i128, ParseDurationError> {
    let (negative, digits) = match number.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, number.strip_prefix('+').unwrap_or(number)),
    };
    let (whole, fraction) = digits.split_once('.').unwrap_or((digits, ""));
    let all_digits = |part: &str| part.bytes().all(|b| b.is_ascii_digit());
    if (whole.is_empty() && fraction.is_empty()) || !all_digits(whole) || !all_digits(fraction) {
        return Err(ParseDurationError::NotANumber);
    }
    // Whole iff the fraction, without its trailing zeros, has no more digits than the unit has
    // microsecond places; then the whole digits, the fraction and its padding are the count.
    let fraction = fraction.trim_end_matches('0');
    if fraction.len() > scale_digits {
        return Err(ParseDurationError::NotWhole);
    }
    let padding = std::iter::repeat_n(b'0', scale_digits - fraction.len());
    let mut us: i128 = 0;
    for b in whole.bytes().chain(fraction.bytes()).chain(padding) {
        us = us
            .checked_mul(10)
            .and_then(|v| v.checked_add(i128::from(b - b'0')))
            .ok_or(ParseDurationError::TooLong)?;
    }
    Ok(if negative { -us } else { us })
}

impl fmt::Display for Micros {
    /// The largest unit that shows the duration exactly (`2ms`, `1500us`, `3s`), so a SPEC
    /// written back parses to the same duration.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            us if us % 1_000_000 == 0 => write!(f, "{}s", us / 1_000_000),
            us if us % 1_000 == 0 => write!(f, "{}ms", us / 1_000),
            us => write!(f, "{us}us"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn us(s: &str) -> Result<i64, ParseDurationError> {
        s.parse::<Micros>().map(Micros::get)
    }

    #[test]
    fn units_and_decimals_are_exact() {
        assert_eq!(us("500us"), Ok(500));
        assert_eq!(us("500µs"), Ok(500));
        assert_eq!(us("2ms"), Ok(2_000));
        assert_eq!(us("1.5ms"), Ok(1_500));
        assert_eq!(us("0.001s"), Ok(1_000));
        assert_eq!(us(" 3 s "), Ok(3_000_000));
        assert_eq!(us(".5ms"), Ok(500));
        assert_eq!(us("9223372036854775807us"), Ok(i64::MAX));
        assert_eq!(
            us("1.000000000000000000000000000000000000000000000s"),
            Ok(1_000_000)
        );
    }

    #[test]
    fn bad_durations_say_why() {
        use ParseDurationError::*;
        assert_eq!(us(""), Err(Empty));
        assert_eq!(us("2"), Err(NoUnit));
        assert_eq!(us("2min"), Err(UnknownUnit));
        assert_eq!(us("ms"), Err(NotANumber));
        assert_eq!(us("1e3us"), Err(UnknownUnit));
        assert_eq!(us("1.2.3ms"), Err(NotANumber));
        assert_eq!(us("0ms"), Err(NotPositive));
        assert_eq!(us("-5ms"), Err(NotPositive));
        assert_eq!(us("0.5us"), Err(NotWhole));
        assert_eq!(us("9223372036854775808us"), Err(TooLong));
        assert_eq!(
            us("99999999999999999999999999999999999999999s"),
            Err(TooLong)
        );
    }

    #[test]
    fn display_round_trips() {
        for v in [1, 999, 1_000, 1_500, 2_000_000, 2_000_001, i64::MAX] {
            let d = Micros::new(v).unwrap();
            assert_eq!(d.to_string().parse::<Micros>(), Ok(d));
        }
        assert_eq!(Micros::new(2_000).unwrap().to_string(), "2ms");
        assert_eq!(Micros::new(0), None);
    }
}
