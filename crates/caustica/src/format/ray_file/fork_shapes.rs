//! Metaballs as the course forks spell them, for both readers:
//!
//! - `metaballs { material; }` (HKUST 2019, danvim/COMP4411-Trace): three balls of radius 1 at
//!   (0, 0, 0), (1, 0.5, 0) and (0, 0.9, 0), blended as a field at level 0.25 (the fork fixed
//!   them in its code); `balls = ((x, y, z), (x, y, z, r), …)`, `radius` and `threshold`
//!   (caustica's spellings) change them;
//! - `metaball { size = R; ball = ((x, y, z), …); }` (COMP4411-Team/Trace): spheres of radius
//!   `size` joined by a polynomial smooth minimum of width 0.7 (`blend` changes it).

use super::ast::{ShapeDesc, Span};
use crate::description::{BlobModelDesc, MetaballsDesc};
use crate::ParseError;
use glam::Vec3;

/// Most balls in one metaballs object: every ray step sums them all (the forks use three).
pub(crate) const MAX_BALLS: usize = 256;

/// Most solids in one CSG object: every ray looks for all their crossings.
pub(crate) const MAX_CSG_LEAVES: usize = 256;

/// Fields of `metaballs` and `metaball` besides `material` and `name`.
pub(crate) const METABALL_FIELDS: &[&str] = &["balls", "ball", "radius", "size", "threshold", "blend"];

/// A ball as written: its centre and, when given, its own radius.
type Ball = (Vec3, Option<f32>);

/// The values of a metaballs block as read.
#[derive(Default)]
pub(crate) struct MetaballFields {
    balls: Option<(Vec<Ball>, Span)>,
    radius: Option<(f32, Span)>,
    threshold: Option<(f32, Span)>,
    blend: Option<(f32, Span)>,
}

impl MetaballFields {
    /// `balls`/`ball`: each entry (x, y, z) or (x, y, z, radius).
    pub fn balls(&mut self, balls: Vec<(Vec3, Option<f32>)>, span: Span) -> Result<(), ParseError> {
        if self.balls.replace((balls, span.clone())).is_some() {
            return Err(ParseError::new("the metaballs have a second list of balls", span));
        }
        Ok(())
    }

    /// `radius`/`size`, `threshold` or `blend`.
    pub fn number(&mut self, key: &str, value: f32, span: Span) -> Result<(), ParseError> {
        let slot = match key {
            "radius" | "size" => &mut self.radius,
            "threshold" => &mut self.threshold,
            _ => &mut self.blend,
        };
        if !(value > 0.0 && value.is_finite()) {
            return Err(ParseError::new(format!("`{key}` must be positive, not {value}"), span));
        }
        if slot.replace((value, span.clone())).is_some() {
            return Err(ParseError::new(format!("the metaballs have a second `{key}`"), span));
        }
        Ok(())
    }

    /// The shape: `keyword` is `metaballs` (field) or `metaball` (smooth union); `None` (with a
    /// warning) for a `metaball` without balls, whose fork gave it no default ones.
    pub fn finish(
        self,
        keyword: &str,
        block: &Span,
        warnings: &mut Vec<(String, Span)>,
    ) -> Result<Option<ShapeDesc>, ParseError> {
        let smooth = keyword == "metaball";
        let radius = self.radius.as_ref().map_or(1.0, |(r, _)| *r);
        let balls: Vec<(Vec3, f32)> = match self.balls {
            Some((balls, span)) => {
                if balls.is_empty() {
                    return Err(ParseError::new("the list of balls is empty", span));
                }
                if balls.len() > MAX_BALLS {
                    return Err(ParseError::new(
                        format!(
                            "{} balls in one metaballs object; at most {MAX_BALLS} are read",
                            balls.len()
                        ),
                        span,
                    ));
                }
                if let Some(&(_, Some(r))) = balls
                    .iter()
                    .find(|(_, r)| r.is_some_and(|r| !(r > 0.0 && r.is_finite())))
                {
                    return Err(ParseError::new(
                        format!("a ball's radius must be positive, not {r}"),
                        span,
                    ));
                }
                balls.into_iter().map(|(c, r)| (c, r.unwrap_or(radius))).collect()
            }
            None if smooth => {
                warnings.push((
                    "skipped `metaball { … }` without balls (`ball = ((x, y, z), …);`): there is nothing to draw"
                        .into(),
                    block.clone(),
                ));
                return Ok(None);
            }
            None => [Vec3::ZERO, Vec3::new(1.0, 0.5, 0.0), Vec3::new(0.0, 0.9, 0.0)]
                .into_iter()
                .map(|c| (c, radius))
                .collect(),
        };
        let model = if smooth {
            if let Some((_, span)) = self.threshold {
                return Err(ParseError::new(
                    "`threshold` belongs to `metaballs`; `metaball` blends by `blend`",
                    span,
                ));
            }
            BlobModelDesc::SmoothUnion {
                blend: self.blend.map_or(0.7, |(b, _)| b),
            }
        } else {
            if let Some((_, span)) = self.blend {
                return Err(ParseError::new(
                    "`blend` belongs to `metaball`; `metaballs` sets its level by `threshold`",
                    span,
                ));
            }
            let threshold = self.threshold.map_or(0.25, |(t, _)| t);
            BlobModelDesc::Field { threshold }
        };
        Ok(Some(ShapeDesc::Metaballs(Box::new(MetaballsDesc { balls, model }))))
    }
}

/// Names of the CSG operations (`subtraction` is the HKUST 2019 fork's difference).
pub(crate) fn csg_op(word: &str) -> Option<crate::description::CsgOpDesc> {
    use crate::description::CsgOpDesc;
    match word {
        "union" => Some(CsgOpDesc::Union),
        "intersection" => Some(CsgOpDesc::Intersection),
        "difference" | "subtraction" => Some(CsgOpDesc::Difference),
        _ => None,
    }
}

/// The object for a CSG operation on `operands`, each the objects one operand produced (several
/// from a group, which is their union); at least two operands, none empty.
pub(crate) fn csg_object(
    op: crate::description::CsgOpDesc,
    operands: Vec<Vec<super::ast::ObjectDesc>>,
    span: Span,
) -> Result<super::ast::ObjectDesc, ParseError> {
    use crate::description::CsgDesc;
    if operands.len() < 2 {
        return Err(ParseError::new("a CSG operation needs two or more operands", span));
    }
    let mut joined = Vec::with_capacity(operands.len());
    for mut objects in operands {
        match objects.len() {
            0 => return Err(ParseError::new("a CSG operand is empty", span)),
            1 => joined.push(objects.pop().expect("one")),
            _ => {
                let first_span = objects[0].span.clone();
                joined.push(union_of(objects, first_span));
            }
        }
    }
    let leaves: usize = joined.iter().map(leaf_count).sum();
    if leaves > MAX_CSG_LEAVES {
        return Err(ParseError::new(
            format!("this CSG object has {leaves} solids; at most {MAX_CSG_LEAVES} are read"),
            span,
        ));
    }
    let material = joined[0].material.clone();
    Ok(super::ast::ObjectDesc {
        shape: ShapeDesc::Csg(Box::new(CsgDesc { op, operands: joined })),
        world_from_object: glam::Mat4::IDENTITY,
        material,
        span,
    })
}

fn leaf_count(object: &super::ast::ObjectDesc) -> usize {
    match &object.shape {
        ShapeDesc::Csg(csg) => csg.operands.iter().map(leaf_count).sum(),
        _ => 1,
    }
}

fn union_of(objects: Vec<super::ast::ObjectDesc>, span: Span) -> super::ast::ObjectDesc {
    use crate::description::{CsgDesc, CsgOpDesc};
    super::ast::ObjectDesc {
        material: objects[0].material.clone(),
        shape: ShapeDesc::Csg(Box::new(CsgDesc {
            op: CsgOpDesc::Union,
            operands: objects,
        })),
        world_from_object: glam::Mat4::IDENTITY,
        span,
    }
}
