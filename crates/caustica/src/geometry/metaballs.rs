//! Metaballs: the surface where a smooth function built from balls crosses zero, in two models
//! the course forks use:
//!
//! - [`BlobModel::Field`] (HKUST 2019, danvim/COMP4411-Trace): each ball adds
//!   K(|p − c| / R) = 1 − x³(6x² − 15x + 10) for x = |p − c|/R < 1 (zero beyond); the surface is
//!   where the sum reaches the threshold (0.25 there).
//! - [`BlobModel::SmoothUnion`] (COMP4411-Team/Trace): the balls' signed distances
//!   |p − c| − R folded with the polynomial smooth minimum of width k (0.7 there); the surface is
//!   where it is zero.
//!
//! Both are written as g(p), positive inside, with a Lipschitz bound L: |g(p) − g(q)| ≤ L|p − q|
//! (Σ 1.875/R for the field, since |K'| ≤ 30·¼·¼ = 1.875; 1 for the smooth minimum of distances,
//! whose gradient (1 − h)∇a + h∇b never exceeds 1). A ray is marched by steps of |g|/L, which can
//! never pass over the surface, however thin; a sign change is then pinned down by bisection. A
//! ray leaving the surface is told which side it starts on by the gradient, so it does not find
//! the surface it left.

use super::LocalHit;
use crate::math::{Aabb, Ray, Vec2, Vec3};

/// One ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    /// Centre.
    pub center: Vec3,
    /// Radius of its support (field) or of the sphere (smooth union).
    pub radius: f32,
}

/// How the balls make a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlobModel {
    /// Σ K(|p − c|/R) = threshold.
    Field {
        /// The level of the surface (0 < threshold < 1 for a surface around each ball).
        threshold: f32,
    },
    /// Smooth minimum of the spheres' distances = 0.
    SmoothUnion {
        /// Width of the blend.
        k: f32,
    },
}

/// A set of metaballs in object space.
#[derive(Clone, Debug, PartialEq)]
pub struct Metaballs {
    balls: Vec<Ball>,
    model: BlobModel,
    /// Lipschitz bound of g.
    lipschitz: f32,
    /// How far beyond a ball's radius the surface can reach.
    reach: f32,
    bounds: Aabb,
}

/// Most crossings reported for one ray.
const MAX_CROSSINGS: usize = 16;
/// Most marching steps per ray.
const MAX_STEPS: usize = 4096;

impl Metaballs {
    /// Metaballs of `balls` (positive radii) in `model`; `None` without a ball.
    pub fn new(balls: Vec<Ball>, model: BlobModel) -> Option<Metaballs> {
        if balls.is_empty() || balls.iter().any(|b| !(b.radius > 0.0 && b.radius.is_finite())) {
            return None;
        }
        let (lipschitz, reach) = match model {
            BlobModel::Field { .. } => (balls.iter().map(|b| 1.875 / b.radius).sum(), 0.0),
            // The polynomial smooth minimum lies at most k/4 below the plain minimum.
            BlobModel::SmoothUnion { k } => (1.0, 0.25 * k.max(0.0)),
        };
        let bounds = balls.iter().fold(Aabb::EMPTY, |b, ball| {
            let r = Vec3::splat(ball.radius + reach);
            b.union(Aabb::new(ball.center - r, ball.center + r))
        });
        Some(Metaballs {
            balls,
            model,
            lipschitz,
            reach,
            bounds,
        })
    }

    /// The balls.
    pub fn balls(&self) -> &[Ball] {
        &self.balls
    }

    /// Object-space bounds.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// g(p), positive inside, and its gradient.
    pub fn value(&self, p: Vec3) -> (f32, Vec3) {
        match self.model {
            BlobModel::Field { threshold } => {
                let (mut sum, mut grad) = (0.0f32, Vec3::ZERO);
                for ball in &self.balls {
                    let to = p - ball.center;
                    let r = to.length();
                    let x = r / ball.radius;
                    if x >= 1.0 {
                        continue;
                    }
                    sum += 1.0 - x * x * x * (x * (6.0 * x - 15.0) + 10.0);
                    if r > 0.0 {
                        let dk = -30.0 * x * x * (1.0 - x) * (1.0 - x);
                        grad += to * (dk / (ball.radius * r));
                    }
                }
                (sum - threshold, grad)
            }
            BlobModel::SmoothUnion { k } => {
                let (mut d, mut grad) = (f32::INFINITY, Vec3::ZERO);
                for ball in &self.balls {
                    let to = p - ball.center;
                    let r = to.length();
                    let (b, gb) = (r - ball.radius, if r > 0.0 { to / r } else { Vec3::Z });
                    if !d.is_finite() {
                        (d, grad) = (b, gb);
                        continue;
                    }
                    let h = if k > 0.0 {
                        (0.5 + (d - b) / (2.0 * k)).clamp(0.0, 1.0)
                    } else if d > b {
                        1.0
                    } else {
                        0.0
                    };
                    d = d * (1.0 - h) + b * h - k * h * (1.0 - h);
                    grad = grad * (1.0 - h) + gb * h;
                }
                (-d, -grad)
            }
        }
    }

    /// A lower bound on the distance from `p` to the surface.
    pub fn distance_lower_bound(&self, p: Vec3) -> f32 {
        let outside_all = self
            .balls
            .iter()
            .map(|b| (p - b.center).length() - b.radius - self.reach)
            .fold(f32::INFINITY, f32::min)
            .max(0.0);
        outside_all.max(self.value(p).0.abs() / self.lipschitz)
    }

    /// Every crossing of the object-space ray in `(0, t_max)`, ascending, with g's gradient
    /// there (pointing inwards), at most [`MAX_CROSSINGS`].
    pub fn crossings(&self, ray: &Ray, t_max: f32, out: &mut Vec<(f32, Vec3)>) {
        out.clear();
        let len = ray.dir.length();
        if !(len > 0.0 && len.is_finite()) {
            return;
        }
        let Some((t_lo, t_hi)) = self.bounds.intersect(ray.origin, ray.dir.recip(), 0.0, t_max) else {
            return;
        };
        let speed = self.lipschitz * len;
        let at = |t: f32| self.value(ray.origin + ray.dir * t);
        // Which side the ray is on just after it starts: by g, or by its gradient on the surface.
        let (g0, grad0) = at(t_lo);
        let tiny = 1e-6 * (1.0 + self.bounds.extent().max_element()) * self.lipschitz;
        let mut inside = if g0.abs() > tiny {
            g0 > 0.0
        } else {
            grad0.dot(ray.dir) > 0.0
        };
        let min_step = 1e-5 * self.bounds.extent().max_element() / len;
        let mut t = t_lo;
        let mut g = g0;
        for _ in 0..MAX_STEPS {
            if t >= t_hi || out.len() >= MAX_CROSSINGS {
                return;
            }
            let step = (g.abs() / speed).max(min_step);
            let next = (t + step).min(t_hi);
            let (gn, _) = at(next);
            if (gn > 0.0) != inside && gn.abs() > 0.0 {
                // Bisection between the last point on this side and the first past it.
                let (mut a, mut b) = (t, next);
                for _ in 0..40 {
                    let m = 0.5 * (a + b);
                    if m <= a || m >= b {
                        break;
                    }
                    if (at(m).0 > 0.0) == inside {
                        a = m;
                    } else {
                        b = m;
                    }
                }
                let root = 0.5 * (a + b);
                if root > 0.0 && root < t_max {
                    out.push((root, at(root).1));
                }
                inside = !inside;
                t = b;
                g = at(b).0;
                continue;
            }
            t = next;
            g = gn;
        }
    }

    /// The nearest hit in `(0, t_max)` of the object-space ray.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<LocalHit> {
        let mut found = Vec::with_capacity(2);
        self.crossings(ray, t_max, &mut found);
        let &(t, grad) = found.first()?;
        Some(LocalHit {
            t,
            point: ray.origin + ray.dir * t,
            // g grows inwards: the outward normal is against its gradient.
            normal: -grad,
            uv: Vec2::ZERO,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(model: BlobModel) -> Metaballs {
        Metaballs::new(
            vec![Ball {
                center: Vec3::ZERO,
                radius: 1.0,
            }],
            model,
        )
        .unwrap()
    }

    /// One ball of the field model is a sphere of radius x where K(x) = threshold; for 0.25 that
    /// is the root of 1 − x³(6x² − 15x + 10) = 0.25 (x ≈ 0.64056).
    #[test]
    fn one_field_ball_is_a_sphere_of_the_kernels_level() {
        let x = {
            let (mut a, mut b) = (0.0f64, 1.0f64);
            for _ in 0..100 {
                let m = 0.5 * (a + b);
                let k = 1.0 - m * m * m * (m * (6.0 * m - 15.0) + 10.0);
                if k > 0.25 {
                    a = m;
                } else {
                    b = m;
                }
            }
            a as f32
        };
        assert!((x - 0.64056).abs() < 1e-4);
        let m = one(BlobModel::Field { threshold: 0.25 });
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::new(0.0, 0.0, -2.0));
        let mut found = Vec::new();
        m.crossings(&ray, f32::INFINITY, &mut found);
        assert_eq!(found.len(), 2);
        assert!((found[0].0 - (5.0 - x) / 2.0).abs() < 1e-5, "{found:?}");
        assert!((found[1].0 - (5.0 + x) / 2.0).abs() < 1e-5);
        let hit = m.intersect(&ray, f32::INFINITY).unwrap();
        assert!((hit.normal.normalize() - Vec3::Z).length() < 1e-4);
        // From the surface outwards: nothing; inwards: the far side.
        let from = Vec3::new(0.0, 0.0, x);
        assert!(m.intersect(&Ray::new(from, Vec3::Z), f32::INFINITY).is_none());
        let through = m.intersect(&Ray::new(from, -Vec3::Z), f32::INFINITY).unwrap();
        assert!((through.t - 2.0 * x).abs() < 1e-4);
    }

    #[test]
    fn one_smooth_union_ball_is_its_sphere() {
        let m = one(BlobModel::SmoothUnion { k: 0.7 });
        let hit = m
            .intersect(&Ray::new(Vec3::new(3.0, 0.0, 0.0), -Vec3::X), f32::INFINITY)
            .unwrap();
        assert!((hit.t - 2.0).abs() < 1e-5);
    }

    /// The field between two balls: grazing rays just above and below the thinnest waist are
    /// told apart exactly, and every crossing lies on g = 0 within the march's tolerance.
    #[test]
    fn thin_necks_are_not_missed() {
        let balls = vec![
            Ball {
                center: Vec3::new(-0.6, 0.0, 0.0),
                radius: 1.0,
            },
            Ball {
                center: Vec3::new(0.6, 0.0, 0.0),
                radius: 1.0,
            },
        ];
        let m = Metaballs::new(balls, BlobModel::Field { threshold: 0.25 }).unwrap();
        // The waist at x = 0: 2K(√(0.36 + y²)) = 0.25, solved by bisection in y.
        let g = |y: f32| m.value(Vec3::new(0.0, y, 0.0)).0;
        let (mut a, mut b) = (0.0f32, 1.0f32);
        for _ in 0..60 {
            let c = 0.5 * (a + b);
            if g(c) > 0.0 {
                a = c;
            } else {
                b = c;
            }
        }
        let waist = a;
        assert!(waist > 0.05, "{waist}");
        let mut found = Vec::new();
        for (y, hits) in [(waist - 2e-4, 2), (waist + 2e-4, 0)] {
            let ray = Ray::new(Vec3::new(0.0, y, 5.0), -Vec3::Z);
            m.crossings(&ray, f32::INFINITY, &mut found);
            assert_eq!(found.len(), hits, "y = {y} (waist {waist})");
            for &(t, _) in &found {
                assert!(m.value(ray.at(t)).0.abs() < 1e-4);
            }
        }
        // Random rays: every hit is on the surface.
        let mut rng = crate::sampling::Rng::new(4, 0);
        for _ in 0..2000 {
            let origin = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 6.0;
            let target = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 1.2;
            let ray = Ray::new(origin, target - origin);
            m.crossings(&ray, f32::INFINITY, &mut found);
            // An odd number of crossings exactly when the ray starts inside.
            let starts_inside = m.value(ray.origin).0 > 0.0;
            assert_eq!(found.len() % 2 == 1, starts_inside, "{ray:?}: {found:?}");
            for &(t, _) in &found {
                assert!(m.value(ray.at(t)).0.abs() < 1e-4, "{ray:?} at {t}");
            }
        }
    }
}
