"""Geometry: rotations, frames and CRSs, cameras and lens models, collinearity, planes,
raster grids and ray casting on them."""
