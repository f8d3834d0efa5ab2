//! Chi-square goodness-of-fit test of normal samplers (in progress).
