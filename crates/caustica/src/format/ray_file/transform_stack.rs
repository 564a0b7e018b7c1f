//! Transform matrices of both dialects, checked for invertibility, and the stack that flattens them.

use super::ast::Span;
use crate::ParseError;
use glam::{Mat4, Vec3, Vec4};

/// Below this |determinant| a matrix is treated as singular: the renderer must invert it.
const MIN_DETERMINANT: f32 = 1e-30;

/// `translate(x, y, z, …)`.
pub(crate) fn translation(v: Vec3) -> Mat4 {
    Mat4::from_translation(v)
}

/// `scale(s, …)` or `scale(x, y, z, …)`; a zero factor is an error.
pub(crate) fn scaling(v: Vec3, span: &Span) -> Result<Mat4, ParseError> {
    let m = Mat4::from_scale(v);
    check_invertible(m, span, "scale factors must be non-zero")?;
    Ok(m)
}

/// `rotate(ax, ay, az, angle, …)`: `angle` radians about the normalised axis, right-handed.
pub(crate) fn rotation(axis: Vec3, angle: f32, span: &Span) -> Result<Mat4, ParseError> {
    let length = axis.length();
    if !(length.is_finite() && length > 1e-20) {
        return Err(ParseError::new(
            format!("rotation axis ({}, {}, {}) has zero length", axis.x, axis.y, axis.z),
            span.clone(),
        ));
    }
    Ok(Mat4::from_axis_angle(axis / length, angle))
}

/// `transform(r1, r2, r3, r4, …)`: the four tuples are the matrix rows.
pub(crate) fn from_rows(rows: [Vec4; 4], span: &Span) -> Result<Mat4, ParseError> {
    let m = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
    check_invertible(m, span, "the matrix must be invertible")?;
    Ok(m)
}

fn check_invertible(m: Mat4, span: &Span, what: &str) -> Result<(), ParseError> {
    let det = m.determinant();
    if !det.is_finite() {
        Err(ParseError::new(
            "transform is too large: its determinant overflows",
            span.clone(),
        ))
    } else if det.abs() >= MIN_DETERMINANT {
        Ok(())
    } else {
        Err(ParseError::new(
            format!("singular transform (determinant {det}): {what}"),
            span.clone(),
        ))
    }
}

/// `parent · local`, checked: many nested factors can overflow or underflow `f32`.
pub(crate) fn compose(parent: Mat4, local: Mat4, span: &Span) -> Result<Mat4, ParseError> {
    let world = parent * local;
    let det = world.determinant();
    if world.is_finite() && det.is_finite() && det.abs() >= MIN_DETERMINANT {
        Ok(world)
    } else {
        Err(ParseError::new(
            "the combined transform of the enclosing transforms overflows or becomes singular",
            span.clone(),
        ))
    }
}

/// The world matrices of the transforms enclosing the current element, outermost first.
#[derive(Debug)]
pub(crate) struct TransformStack {
    stack: Vec<Mat4>,
}

impl TransformStack {
    /// A stack holding only the identity.
    pub fn new() -> TransformStack {
        TransformStack {
            stack: vec![Mat4::IDENTITY],
        }
    }

    /// The current object-to-world matrix.
    pub fn current(&self) -> Mat4 {
        self.stack.last().copied().unwrap_or(Mat4::IDENTITY)
    }

    /// Enters a transform: the new current matrix is current · local (checked by [`compose`]).
    pub fn push(&mut self, local: Mat4, span: &Span) -> Result<(), ParseError> {
        let world = compose(self.current(), local, span)?;
        self.stack.push(world);
        Ok(())
    }

    /// Leaves the innermost transform.
    pub fn pop(&mut self) {
        if self.stack.len() > 1 {
            self.stack.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_is_right_handed_radians() {
        let m = rotation(Vec3::new(0.0, 0.0, 2.0), std::f32::consts::FRAC_PI_2, &(0..1)).expect("valid axis");
        let p = m.transform_point3(Vec3::X);
        assert!((p - Vec3::Y).length() < 1e-6, "{p}");
    }

    #[test]
    fn rows_put_translation_in_the_fourth_column() {
        let rows = [
            Vec4::new(1.0, 0.0, 0.0, 5.0),
            Vec4::new(0.0, 1.0, 0.0, 6.0),
            Vec4::new(0.0, 0.0, 1.0, 7.0),
            Vec4::new(0.0, 0.0, 0.0, 1.0),
        ];
        let m = from_rows(rows, &(0..1)).expect("invertible");
        assert_eq!(m.transform_point3(Vec3::ZERO), Vec3::new(5.0, 6.0, 7.0));
    }

    #[test]
    fn degenerate_matrices_are_rejected() {
        assert!(rotation(Vec3::ZERO, 1.0, &(3..9)).is_err());
        assert_eq!(scaling(Vec3::new(1.0, 0.0, 1.0), &(3..9)).expect_err("zero").span, 3..9);
        assert!(from_rows([Vec4::ZERO; 4], &(0..1)).is_err());
    }

    #[test]
    fn stack_composes_parent_first() {
        let mut stack = TransformStack::new();
        stack.push(translation(Vec3::X), &(0..1)).expect("ok");
        stack
            .push(scaling(Vec3::splat(2.0), &(0..1)).expect("ok"), &(0..1))
            .expect("ok");
        assert_eq!(stack.current().transform_point3(Vec3::X), Vec3::new(3.0, 0.0, 0.0));
        stack.pop();
        assert_eq!(stack.current().transform_point3(Vec3::X), Vec3::new(2.0, 0.0, 0.0));
        let huge = scaling(Vec3::splat(1e12), &(0..1)).expect("ok");
        assert!(stack
            .push(huge, &(0..1))
            .and_then(|_| stack.push(huge, &(0..1)))
            .is_err());
    }
}
