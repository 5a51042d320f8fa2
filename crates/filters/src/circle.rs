//! `circle=CX,CY,R`: keeps the events inside a disc, boundary included:
//! `(x - CX)^2 + (y - CY)^2 <= R^2`, pixel coordinates as they are (pixel `(x, y)` at `x, y`,
//! not at its centre `x + 0.5`). The arithmetic is f64, exact whenever CX, CY and R have few
//! binary digits (whole numbers, halves, quarters), so a pixel on the circle is kept.
//!
//! No dv-processing class does this (`dv::EventMaskFilter` would, from a mask image); a
//! NeuroTac's pins sit in a disc, and this keeps the dome's image without its surroundings.

use evtac_events::Event;

use crate::Rule;

/// Keeps the events inside a disc.
#[derive(Debug, Clone)]
pub struct Circle {
    cx: f64,
    cy: f64,
    radius_squared: f64,
}

impl Circle {
    /// Keeps the events within `radius` of `(cx, cy)`.
    pub fn new(cx: f64, cy: f64, radius: f64) -> Self {
        Self {
            cx,
            cy,
            radius_squared: radius * radius,
        }
    }
}

impl Rule for Circle {
    const NAME: &'static str = "circle";

    #[inline]
    fn accept(&mut self, event: &Event) -> bool {
        let dx = f64::from(event.x) - self.cx;
        let dy = f64::from(event.y) - self.cy;
        dx * dx + dy * dy <= self.radius_squared
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Filter;

    #[test]
    fn the_boundary_is_inside() {
        let mut f = Circle::new(10.0, 10.0, 5.0).counted();
        let keep = |f: &mut crate::Counted<Circle>, x, y| {
            f.keep(&Event {
                t: 0,
                x,
                y,
                polarity: true,
            })
        };
        assert!(keep(&mut f, 10, 10));
        assert!(keep(&mut f, 15, 10));
        assert!(keep(&mut f, 13, 14));
        assert!(!keep(&mut f, 14, 14));
        assert!(!keep(&mut f, 10, 16));
        let mut half = Circle::new(0.5, 0.5, 0.75).counted();
        assert!(keep(&mut half, 0, 0) && keep(&mut half, 1, 1) && !keep(&mut half, 2, 0));
        assert_eq!(f.removed(), 2);
    }
}
