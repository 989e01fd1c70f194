//! Exact solutions of the shallow-water equations (no bottom, no drag) that the scheme is
//! checked against: the dam breaks of Ritter (1892, dry bed downstream) and Stoker (1957,
//! wet bed downstream), self-similar in xi = (x - x0)/t, and the Rankine-Hugoniot bore.

/// A dam at x0 holding depth `left` against depth `right` < `left` (0: dry), both at rest,
/// under gravity `g`.
#[derive(Clone, Copy, Debug)]
pub struct DamBreak {
    pub left: f64,
    pub right: f64,
    pub g: f64,
}

/// The state between the rarefaction and the bore of a wet dam break, and the bore's speed.
#[derive(Clone, Copy, Debug)]
pub struct Middle {
    pub depth: f64,
    pub velocity: f64,
    pub bore_speed: f64,
}

impl DamBreak {
    /// The middle state of Stoker's solution: the left rarefaction's Riemann invariant
    /// u + 2c = 2 c_L and the bore's Rankine-Hugoniot conditions into still water,
    /// u = (h - h_R) sqrt(g (h + h_R) / (2 h h_R)), meet; solved by bisection in h.
    pub fn middle(&self) -> Middle {
        let (hl, hr, g) = (self.left, self.right, self.g);
        let cl = (g * hl).sqrt();
        let mismatch = |h: f64| {
            let rarefaction = 2.0 * (cl - (g * h).sqrt());
            let bore = (h - hr) * (g * (h + hr) / (2.0 * h * hr)).sqrt();
            rarefaction - bore
        };
        // The rarefaction's velocity falls with h, the bore's rises: one root in (h_R, h_L).
        let (mut lo, mut hi) = (hr, hl);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mismatch(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let h = 0.5 * (lo + hi);
        let u = 2.0 * (cl - (g * h).sqrt());
        Middle {
            depth: h,
            velocity: u,
            // Mass conservation across the bore: h (S - u) = h_R S.
            bore_speed: h * u / (h - hr),
        }
    }

    /// Depth and velocity at xi = (x - x0)/t.
    pub fn at(&self, xi: f64) -> (f64, f64) {
        let g = self.g;
        let cl = (g * self.left).sqrt();
        // The centred rarefaction: u + 2c = 2 c_L and xi = u - c.
        let fan = |xi: f64| {
            let c = (2.0 * cl - xi) / 3.0;
            (c * c / g, 2.0 * (cl + xi) / 3.0)
        };
        if xi <= -cl {
            return (self.left, 0.0);
        }
        if self.right <= 0.0 {
            // Ritter: the fan reaches the dry bed at xi = 2 c_L.
            return if xi < 2.0 * cl { fan(xi) } else { (0.0, 0.0) };
        }
        let m = self.middle();
        let tail = m.velocity - (g * m.depth).sqrt();
        if xi < tail {
            fan(xi)
        } else if xi < m.bore_speed {
            (m.depth, m.velocity)
        } else {
            (self.right, 0.0)
        }
    }

    /// Energy lost per unit time at the bore, per unit breadth and density [m^4/s^3]: the
    /// head loss (h - h_R)^3 / (4 h h_R) of the hydraulic jump times g and the discharge
    /// h_R S through it (Rankine-Hugoniot).
    pub fn bore_dissipation(&self) -> f64 {
        let m = self.middle();
        let (h, hr) = (m.depth, self.right);
        self.g * hr * m.bore_speed * (h - hr).powi(3) / (4.0 * h * hr)
    }
}
