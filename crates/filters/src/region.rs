//! `region=X,Y,W,H`: dv-processing's `dv::EventRegionFilter`
//! (`include/dv-processing/core/filters.hpp`), which keeps the events inside a `cv::Rect`:
//! `X <= x < X + W` and `Y <= y < Y + H`, the left and top edges in, the right and bottom ones
//! out.

use evtac_events::Event;

use crate::Rule;

/// Keeps the events inside a rectangle.
#[derive(Debug, Clone)]
pub struct Region {
    x: u32,
    y: u32,
    width: u32,
    height: u32,
}

impl Region {
    /// Keeps `x <= e.x < x + width` and `y <= e.y < y + height`.
    pub fn new(x: u16, y: u16, width: u16, height: u16) -> Self {
        // u32: `x + width` may pass 65535.
        Self {
            x: u32::from(x),
            y: u32::from(y),
            width: u32::from(width),
            height: u32::from(height),
        }
    }
}

impl Rule for Region {
    const NAME: &'static str = "region";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        let (x, y) = (u32::from(event.x), u32::from(event.y));
        // `&`, not `&&`: both tests are cheap, and a short-circuit would be a branch on where
        // the event is, which the stream decides.
        (self.x..self.x + self.width).contains(&x) & (self.y..self.y + self.height).contains(&y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    #[test]
    fn left_and_top_edges_in_right_and_bottom_out() {
        let mut f = Region::new(2, 3, 4, 5).counted();
        let keep = |f: &mut crate::Counted<Region>, x, y| {
            f.keep(&Event {
                t: 0,
                x,
                y,
                polarity: true,
            })
        };
        assert!(keep(&mut f, 2, 3));
        assert!(keep(&mut f, 5, 7));
        assert!(!keep(&mut f, 6, 7));
        assert!(!keep(&mut f, 5, 8));
        assert!(!keep(&mut f, 1, 4));
        assert!(!keep(&mut f, 3, 2));
        assert_eq!(f.removed(), 4);
    }
}
