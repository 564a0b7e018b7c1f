//! Real roots of a polynomial (degree ≤ 4) in an interval, found robustly: between consecutive
//! roots of the derivative (found the same way, recursively) the polynomial is monotone, so a
//! sign change there brackets exactly one root, which safeguarded Newton steps then pin down.
//! Only tangent (even-multiplicity) roots are missed, as a ray grazing a surface may be.

/// Up to four roots, in ascending order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Roots {
    values: [f64; 4],
    len: usize,
}

impl Roots {
    /// Adds a root (ascending order is the caller's), unless it repeats the last one.
    pub fn push(&mut self, x: f64) {
        // A root found at the shared end of two monotone pieces is one root.
        if self.len > 0 && (x - self.values[self.len - 1]).abs() <= 1e-12 * (1.0 + x.abs()) {
            return;
        }
        if self.len < 4 {
            self.values[self.len] = x;
            self.len += 1;
        }
    }

    /// The roots found.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

/// Value of the polynomial with coefficients `c` (constant first) at `x`.
#[inline]
pub fn eval(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * x + k)
}

/// The real roots of the polynomial `c` (constant first, degree ≤ 4) in `[lo, hi]`, ascending.
pub fn roots_in(c: &[f64], lo: f64, hi: f64) -> Roots {
    let mut out = Roots::default();
    // Drop vanishing leading coefficients (relative to the others).
    let scale = c.iter().fold(0.0f64, |m, k| m.max(k.abs()));
    let mut degree = c.len().saturating_sub(1);
    while degree > 0 && c[degree].abs() <= 1e-14 * scale {
        degree -= 1;
    }
    let c = &c[..=degree];
    if degree == 0 || lo.is_nan() || hi.is_nan() || lo > hi {
        return out;
    }
    if degree == 1 {
        let x = -c[0] / c[1];
        if (lo..=hi).contains(&x) {
            out.push(x);
        }
        return out;
    }
    let derivative: Vec<f64> = (1..=degree).map(|i| c[i] * i as f64).collect();
    let critical = roots_in(&derivative, lo, hi);
    let mut a = lo;
    let mut fa = eval(c, a);
    for &b in critical.as_slice().iter().chain(std::iter::once(&hi)) {
        let fb = eval(c, b);
        if fa == 0.0 {
            out.push(a);
        } else if fa.signum() != fb.signum() && fb != 0.0 {
            out.push(monotone_root(c, &derivative, a, b, fa));
        }
        a = b;
        fa = fb;
    }
    if fa == 0.0 {
        out.push(a);
    }
    out
}

/// The root of `c` in `(a, b)`, where `c` is monotone and changes sign (`fa` = c(a)).
fn monotone_root(c: &[f64], derivative: &[f64], mut a: f64, mut b: f64, fa: f64) -> f64 {
    let mut x = 0.5 * (a + b);
    for _ in 0..100 {
        let fx = eval(c, x);
        if fx == 0.0 {
            return x;
        }
        if fx.signum() == fa.signum() {
            a = x;
        } else {
            b = x;
        }
        // A Newton step where it stays inside the bracket, bisection otherwise.
        let d = eval(derivative, x);
        let newton = x - fx / d;
        x = if d != 0.0 && newton > a && newton < b {
            newton
        } else {
            0.5 * (a + b)
        };
        if (b - a) <= 1e-15 * (1.0 + a.abs().max(b.abs())) {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficients (constant first) of Π (x − r).
    fn from_roots(roots: &[f64]) -> Vec<f64> {
        let mut c = vec![1.0];
        for &r in roots {
            let mut next = vec![0.0; c.len() + 1];
            for (i, &k) in c.iter().enumerate() {
                next[i + 1] += k;
                next[i] -= r * k;
            }
            c = next;
        }
        c
    }

    #[test]
    fn finds_every_simple_root_in_the_interval() {
        for roots in [
            vec![-1.5, 0.25, 0.3, 2.0],
            vec![1e-3, 1.0 + 1e-6, 1.0 + 3e-6, 7.0],
            vec![0.5, 1.5, 2.5],
            vec![-0.75, 0.125],
            vec![3.0],
        ] {
            let c = from_roots(&roots);
            let found = roots_in(&c, -10.0, 10.0);
            assert_eq!(found.as_slice().len(), roots.len(), "{roots:?}: {found:?}");
            for (f, r) in found.as_slice().iter().zip(&roots) {
                assert!((f - r).abs() < 1e-9 * (1.0 + r.abs()), "{roots:?}: {f} vs {r}");
            }
            let inner = roots_in(&c, 0.2, 2.1);
            let expected: Vec<f64> = roots.iter().copied().filter(|r| (0.2..=2.1).contains(r)).collect();
            assert_eq!(inner.as_slice().len(), expected.len(), "{roots:?} in [0.2, 2.1]");
        }
        // (x² + 1)(x² + 4) has no real root.
        assert!(roots_in(&[4.0, 0.0, 5.0, 0.0, 1.0], -10.0, 10.0).as_slice().is_empty());
        // A root on the boundary counts once.
        assert_eq!(roots_in(&from_roots(&[1.0, 2.0]), 1.0, 3.0).as_slice(), &[1.0, 2.0]);
    }
}
