//! A block of sampled directions, component by component: what [`super::Bsdf::sample_wo_batch`]
//! writes and the BSDF chi-square bins. Three arrays x, y, z and a flag per element (a
//! structure of arrays) rather than `Option<Vec3>`s, so that the vectorized passes on both
//! sides — the reference BSDFs' scatter and the chi-square's cell finder — load and store whole
//! vectors: interleaving the directions with their `Option` tags, and splitting them again,
//! was a tenth of the BSDF chi-square's time.

use crate::geometry::Vec3;

/// Sampled directions: element k is `Some([x[k], y[k], z[k]])` where `sampled[k]`, else a
/// failed sample (its components unspecified).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Directions {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    sampled: Vec<bool>,
}

/// The components and flags of a run of [`Directions`], borrowed for writing.
#[derive(Debug)]
pub struct DirectionsMut<'a> {
    /// x, y and z.
    pub xyz: [&'a mut [f64]; 3],
    /// Whether each element is a sample.
    pub sampled: &'a mut [bool],
}

impl Directions {
    /// `n` failed samples.
    pub fn new(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            y: vec![0.0; n],
            z: vec![0.0; n],
            sampled: vec![false; n],
        }
    }

    /// The directions of `w`.
    pub fn from_options(w: &[Option<Vec3>]) -> Self {
        let mut d = Self::new(w.len());
        for (k, &w) in w.iter().enumerate() {
            d.set(k, w);
        }
        d
    }

    /// The number of elements.
    pub fn len(&self) -> usize {
        self.sampled.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.sampled.is_empty()
    }

    /// Makes the length `n`, new elements failed samples (the others kept).
    pub fn resize(&mut self, n: usize) {
        for c in [&mut self.x, &mut self.y, &mut self.z] {
            c.resize(n, 0.0);
        }
        self.sampled.resize(n, false);
    }

    /// Marks every element a failed sample.
    pub fn fail_all(&mut self) {
        self.sampled.fill(false);
    }

    /// Element k.
    ///
    /// # Panics
    /// If k is out of bounds.
    pub fn get(&self, k: usize) -> Option<Vec3> {
        self.sampled[k].then(|| [self.x[k], self.y[k], self.z[k]])
    }

    /// Sets element k.
    ///
    /// # Panics
    /// If k is out of bounds.
    pub fn set(&mut self, k: usize, w: Option<Vec3>) {
        let v = w.unwrap_or([0.0; 3]);
        (self.x[k], self.y[k], self.z[k]) = (v[0], v[1], v[2]);
        self.sampled[k] = w.is_some();
    }

    /// The elements in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Option<Vec3>> + '_ {
        (0..self.len()).map(|k| self.get(k))
    }

    /// The components x, y, z and the flags, each of [`Directions::len`] elements.
    pub fn components(&self) -> ([&[f64]; 3], &[bool]) {
        ([&self.x, &self.y, &self.z], &self.sampled)
    }

    /// The components and flags for writing.
    pub fn as_mut(&mut self) -> DirectionsMut<'_> {
        DirectionsMut {
            xyz: [&mut self.x, &mut self.y, &mut self.z],
            sampled: &mut self.sampled,
        }
    }
}

impl<'a> DirectionsMut<'a> {
    /// The number of elements.
    pub fn len(&self) -> usize {
        self.sampled.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.sampled.is_empty()
    }

    /// Runs of at most `n` elements (the last shorter), in order, as `slice::chunks_mut`.
    ///
    /// # Panics
    /// If n is 0.
    pub fn chunks(self, n: usize) -> impl Iterator<Item = DirectionsMut<'a>> {
        let [x, y, z] = self.xyz;
        x.chunks_mut(n)
            .zip(y.chunks_mut(n))
            .zip(z.chunks_mut(n))
            .zip(self.sampled.chunks_mut(n))
            .map(|(((x, y), z), sampled)| DirectionsMut {
                xyz: [x, y, z],
                sampled,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_keep_what_is_set_and_chunks_cover_them_in_order() {
        let w = [Some([0.1, 0.2, 0.3]), None, Some([-1.0, 0.0, -0.0])];
        let mut d = Directions::from_options(&w);
        assert_eq!(d.iter().collect::<Vec<_>>(), w);
        assert_eq!((d.len(), d.is_empty()), (3, false));
        d.resize(5);
        assert_eq!(d.get(4), None);
        assert_eq!(d.get(2), w[2]);
        let lengths: Vec<usize> = d.as_mut().chunks(2).map(|c| c.len()).collect();
        assert_eq!(lengths, [2, 2, 1]);
        for (k, c) in d.as_mut().chunks(2).enumerate() {
            c.xyz[0][0] = k as f64;
            c.sampled[0] = true;
        }
        assert_eq!(d.get(2), Some([1.0, 0.0, -0.0]));
        assert_eq!(d.get(4), Some([2.0, 0.0, 0.0]));
        d.fail_all();
        assert!(d.iter().all(|w| w.is_none()));
        assert!(Directions::default().is_empty());
    }
}
