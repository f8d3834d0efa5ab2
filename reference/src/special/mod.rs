//! Special functions no well-kept crate provides at the accuracy and over the domain the
//! closed forms need; everything else comes from statrs and libm.

mod beckmann_fit;
pub mod gamma_ratio;
pub mod gauss_kronrod;
pub mod hyp2f1;
pub mod student_tail;
