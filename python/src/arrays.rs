//! Images as numpy arrays: (height, width, 3) float32, rows from the top, linear RGB.

use crate::to_py;
use caustica::film::Film;
use caustica::math::Vec3;
use numpy::{PyArray1, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;

/// An image's pixels as an array of shape (height, width, 3).
pub fn image_array<'py>(
    py: Python<'py>,
    width: usize,
    height: usize,
    pixels: &[Vec3],
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let data: Vec<f32> = pixels.iter().flat_map(|p| p.to_array()).collect();
    PyArray1::from_vec(py, data).reshape([height, width, 3])
}

/// A film as an array of shape (height, width, 3).
pub fn film_array<'py>(py: Python<'py>, film: &Film) -> PyResult<Bound<'py, PyArray3<f32>>> {
    image_array(py, film.width, film.height, &film.pixels)
}

/// Reads an OpenEXR file (such as `caustica render -o x.exr` writes) as a float32 array of
/// shape (height, width, 3), linear RGB, rows from the top.
#[pyfunction]
pub fn read_exr(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let (width, height, pixels) = py
        .detach(|| caustica::image_io::read_exr(&path))
        .map_err(|e| to_py(py, e))?;
    image_array(py, width, height, &pixels)
}
