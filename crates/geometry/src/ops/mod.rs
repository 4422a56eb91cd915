//! Sets built from other sets through support functions.
pub mod linear_image;
pub mod minkowski_sum;

pub use linear_image::LinearImage;
pub use minkowski_sum::MinkowskiSum;
