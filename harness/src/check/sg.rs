//! Spherical Gaussians (placeholder).
