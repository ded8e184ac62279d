//! An array of 3-vectors stored as three arrays of components (structure of arrays).
//!
//! The force pass reads the per-pair rest data four pairs at a time, one SIMD register per
//! component (see [`crate::kernels::lanes`]); with the components apart, those are plain contiguous
//! loads instead of strided gathers.

use crate::kernels::math::{Real, Vec3};

/// 3-vectors (any unit) by component: `x[e], y[e], z[e]` is vector `e`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Vec3Array {
    /// First components.
    pub x: Vec<Real>,
    /// Second components.
    pub y: Vec<Real>,
    /// Third components.
    pub z: Vec<Real>,
}

impl Vec3Array {
    /// Vector `e`.
    #[inline]
    pub fn get(&self, e: usize) -> Vec3 {
        Vec3::new(self.x[e], self.y[e], self.z[e])
    }
    /// Set vector `e` to `v`.
    #[inline]
    pub fn set(&mut self, e: usize, v: Vec3) {
        self.x[e] = v.x;
        self.y[e] = v.y;
        self.z[e] = v.z;
    }
    /// Append `v`.
    pub fn push(&mut self, v: Vec3) {
        self.x.push(v.x);
        self.y.push(v.y);
        self.z.push(v.z);
    }
    /// The vectors of `range`, in order.
    pub fn iter_range(&self, range: std::ops::Range<usize>) -> impl Iterator<Item = Vec3> + '_ {
        range.map(move |e| self.get(e))
    }
    /// Overwrite with `other` (of the same length).
    pub fn copy_from(&mut self, other: &Vec3Array) {
        self.x.copy_from_slice(&other.x);
        self.y.copy_from_slice(&other.y);
        self.z.copy_from_slice(&other.z);
    }
    /// Bytes of heap memory the components occupy (their lengths).
    pub fn heap_bytes(&self) -> usize {
        3 * std::mem::size_of_val(self.x.as_slice())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_round_trip_through_the_components() {
        let vs = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-4.0, 5.5, 0.0)];
        let mut a = Vec3Array::default();
        vs.iter().for_each(|v| a.push(*v));
        assert_eq!(a.get(1), vs[1]);
        a.set(0, Vec3::new(7.0, 8.0, 9.0));
        assert_eq!(a.x, vec![7.0, -4.0]);
        assert_eq!(
            a.iter_range(0..2).collect::<Vec<_>>()[0],
            Vec3::new(7.0, 8.0, 9.0)
        );
        assert_eq!(a.heap_bytes(), 2 * 3 * 8);
    }
}
