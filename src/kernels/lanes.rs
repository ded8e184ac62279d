//! Four `f64` lanes for the force pass's inner loops, on `wide::f64x4`: one AVX register in a
//! build for x86-64-v3 (this repository's default, `.cargo/config.toml`), two SSE2 registers on
//! baseline x86-64, two NEON registers on aarch64, plain arrays elsewhere.
//!
//! Every operation is lane-wise IEEE arithmetic in a fixed order, without reassociation: a lane
//! gives the bits it would give alone, on any number of threads. Products that are added (dot
//! and cross products, matrix–vector products, outer-product sums and the explicit
//! `mul_add`-style methods) use a fused multiply–add, rounded once, where the build targets
//! FMA on x86-64 (x86-64-v3, this repository's default); elsewhere (baseline x86-64, aarch64)
//! `wide` rounds the product, then the sum. So a build with FMA and one without differ in the
//! last bits; each is deterministic. Only [`F4::sum`] crosses lanes, in a fixed order.

use crate::kernels::math::{Mat3, Real, Vec3};
use std::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};
use wide::{f64x4, CmpLe, CmpLt};

/// Lane count.
pub(crate) const LANES: usize = 4;

/// Four lanes of [`Real`] (any unit).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct F4(f64x4);

impl F4 {
    /// All lanes `v`.
    #[inline(always)]
    pub(crate) fn splat(v: Real) -> F4 {
        F4(f64x4::splat(v))
    }
    /// The lanes `a`.
    #[inline(always)]
    pub(crate) fn new(a: [Real; LANES]) -> F4 {
        F4(f64x4::new(a))
    }
    /// The lanes as an array.
    #[inline(always)]
    pub(crate) fn to_array(self) -> [Real; LANES] {
        self.0.to_array()
    }
    /// Lane-wise square root (correctly rounded, as the scalar one).
    #[inline(always)]
    pub(crate) fn sqrt(self) -> F4 {
        F4(self.0.sqrt())
    }
    /// Lane-wise maximum; where `self` is NaN, `o` (as the scalar `max`).
    #[inline(always)]
    pub(crate) fn max(self, o: F4) -> F4 {
        F4(self.0.max(o.0))
    }
    /// The lanes where `self < o` (false where either is NaN).
    #[inline(always)]
    pub(crate) fn lt(self, o: F4) -> Mask4 {
        Mask4(self.0.cmp_lt(o.0))
    }
    /// The lanes where `self <= o` (false where either is NaN).
    #[inline(always)]
    pub(crate) fn le(self, o: F4) -> Mask4 {
        Mask4(self.0.cmp_le(o.0))
    }
    /// Lane-wise `self * m + a`, rounded once where the build has FMA (see the module doc).
    #[inline(always)]
    pub(crate) fn mul_add(self, m: F4, a: F4) -> F4 {
        F4(self.0.mul_add(m.0, a.0))
    }
    /// Lane-wise `self * m - a`, rounded once where the build has FMA.
    #[inline(always)]
    pub(crate) fn mul_sub(self, m: F4, a: F4) -> F4 {
        F4(self.0.mul_sub(m.0, a.0))
    }
    /// Lane-wise `a - self * m`, rounded once where the build has FMA.
    #[inline(always)]
    pub(crate) fn mul_neg_add(self, m: F4, a: F4) -> F4 {
        F4(self.0.mul_neg_add(m.0, a.0))
    }
    /// The lanes `[l1, l2, l0, l3]`: a 3-vector in the first three lanes, rotated to y, z, x.
    /// One permutation with AVX2 (so stored, it is one whole vector), otherwise lane by lane.
    #[inline(always)]
    pub(crate) fn rotate_yzx(self) -> F4 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return F4(avx2::permute::<0b11_00_10_01>(self.0));
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        {
            let [x, y, z, w] = self.to_array();
            F4::new([y, z, x, w])
        }
    }
    /// The lanes `[l2, l0, l1, l3]`: a 3-vector in the first three lanes, rotated to z, x, y
    /// (as [`F4::rotate_yzx`]).
    #[inline(always)]
    pub(crate) fn rotate_zxy(self) -> F4 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
        return F4(avx2::permute::<0b11_01_00_10>(self.0));
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
        {
            let [x, y, z, w] = self.to_array();
            F4::new([z, x, y, w])
        }
    }
    /// `(l0 + l1) + (l2 + l3)`.
    #[inline(always)]
    pub(crate) fn sum(self) -> Real {
        let [a, b, c, d] = self.to_array();
        (a + b) + (c + d)
    }
}

impl Add for F4 {
    type Output = F4;
    #[inline(always)]
    fn add(self, o: F4) -> F4 {
        F4(self.0 + o.0)
    }
}

impl Sub for F4 {
    type Output = F4;
    #[inline(always)]
    fn sub(self, o: F4) -> F4 {
        F4(self.0 - o.0)
    }
}

impl Mul for F4 {
    type Output = F4;
    #[inline(always)]
    fn mul(self, o: F4) -> F4 {
        F4(self.0 * o.0)
    }
}

impl Div for F4 {
    type Output = F4;
    #[inline(always)]
    fn div(self, o: F4) -> F4 {
        F4(self.0 / o.0)
    }
}

/// The sign bit flipped, as scalar negation does (`0 - x` would give `+0` for `x = +0`).
impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        F4(self.0 ^ f64x4::splat(-0.0))
    }
}

impl AddAssign for F4 {
    #[inline(always)]
    fn add_assign(&mut self, o: F4) {
        *self = *self + o;
    }
}

/// One lane of [`F4::mul_add`]: `a * b + c`, rounded once exactly where the lanes are.
#[inline(always)]
fn mul_add(a: Real, b: Real, c: Real) -> Real {
    if cfg!(all(target_arch = "x86_64", target_feature = "fma")) {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// One lane of [`V4::dot`], the same bits.
#[inline(always)]
pub(crate) fn dot(a: &Vec3, b: &Vec3) -> Real {
    mul_add(a.z, b.z, mul_add(a.y, b.y, a.x * b.x))
}

/// One lane of [`V4::cross`], the same bits.
#[inline(always)]
pub(crate) fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    Vec3::new(
        mul_add(a.y, b.z, -(a.z * b.y)),
        mul_add(a.z, b.x, -(a.x * b.z)),
        mul_add(a.x, b.y, -(a.y * b.x)),
    )
}

/// A true or false per lane, as the comparisons of [`F4`] give it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mask4(f64x4);

impl Mask4 {
    /// Lane `l` is `b[l]`.
    #[inline(always)]
    pub(crate) fn new(b: [bool; LANES]) -> Mask4 {
        Mask4(f64x4::new(b.map(|b| {
            if b {
                f64::from_bits(u64::MAX)
            } else {
                0.0
            }
        })))
    }
    /// Whether any lane is true.
    #[inline(always)]
    pub(crate) fn any(self) -> bool {
        self.0.any()
    }
    /// Whether lane `l` is true.
    #[inline(always)]
    pub(crate) fn lane(self, l: usize) -> bool {
        self.0.move_mask() & (1 << l) != 0
    }
    /// Lane-wise `if self { t } else { f }`, the bits of `t` or `f` unchanged.
    #[inline(always)]
    pub(crate) fn select(self, t: F4, f: F4) -> F4 {
        F4(self.0.blend(t.0, f.0))
    }
}

impl BitAnd for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn bitand(self, o: Mask4) -> Mask4 {
        Mask4(self.0 & o.0)
    }
}

impl BitOr for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn bitor(self, o: Mask4) -> Mask4 {
        Mask4(self.0 | o.0)
    }
}

impl Not for Mask4 {
    type Output = Mask4;
    #[inline(always)]
    fn not(self) -> Mask4 {
        Mask4(!self.0)
    }
}

/// Four 3-vectors (any unit), one lane each: `(x[l], y[l], z[l])` is vector `l`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct V4 {
    pub(crate) x: F4,
    pub(crate) y: F4,
    pub(crate) z: F4,
}

impl V4 {
    /// All lanes `v`.
    #[inline(always)]
    pub(crate) fn splat(v: &Vec3) -> V4 {
        V4 {
            x: F4::splat(v.x),
            y: F4::splat(v.y),
            z: F4::splat(v.z),
        }
    }
    /// `field[j[l]]` in lane `l`, without a check per index.
    ///
    /// # Safety
    /// Every `j[l]` is below `field.len()`.
    #[inline(always)]
    pub(crate) unsafe fn gather_unchecked(field: &[Vec3], j: &[u32; LANES]) -> V4 {
        // SAFETY: the caller's contract.
        let at = |l: usize| unsafe { field.get_unchecked(j[l] as usize) };
        V4::from_refs([at(0), at(1), at(2), at(3)])
    }
    /// Lane `l` is `*a[l]`: four masked loads and a transpose with AVX, otherwise one
    /// component at a time.
    #[inline(always)]
    pub(crate) fn from_refs(a: [&Vec3; LANES]) -> V4 {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
        {
            let [x, y, z] = avx::transpose_in(a);
            V4 {
                x: F4(x),
                y: F4(y),
                z: F4(z),
            }
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
        V4 {
            x: F4::new(a.map(|v| v.x)),
            y: F4::new(a.map(|v| v.y)),
            z: F4::new(a.map(|v| v.z)),
        }
    }
    /// Lane-wise cross product (each component `a b - c d`, the first product fused).
    #[inline(always)]
    pub(crate) fn cross(&self, o: &V4) -> V4 {
        V4 {
            x: self.y.mul_sub(o.z, self.z * o.y),
            y: self.z.mul_sub(o.x, self.x * o.z),
            z: self.x.mul_sub(o.y, self.y * o.x),
        }
    }
    /// Lane-wise dot product.
    #[inline(always)]
    pub(crate) fn dot(&self, o: &V4) -> F4 {
        self.z.mul_add(o.z, self.y.mul_add(o.y, self.x * o.x))
    }
    /// Every lane scaled by the lane's `s`.
    #[inline(always)]
    pub(crate) fn scale(&self, s: F4) -> V4 {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    /// Lane-wise `a + self * s`, rounded once per component where the build has FMA.
    #[inline(always)]
    pub(crate) fn scale_add(&self, s: F4, a: &V4) -> V4 {
        V4 {
            x: self.x.mul_add(s, a.x),
            y: self.y.mul_add(s, a.y),
            z: self.z.mul_add(s, a.z),
        }
    }
    /// Lane-wise `a - self * s`, rounded once per component where the build has FMA.
    #[inline(always)]
    pub(crate) fn scale_sub_from(&self, s: F4, a: &V4) -> V4 {
        V4 {
            x: self.x.mul_neg_add(s, a.x),
            y: self.y.mul_neg_add(s, a.y),
            z: self.z.mul_neg_add(s, a.z),
        }
    }
    /// Lane-wise `if mask { t } else { f }`.
    #[inline(always)]
    pub(crate) fn select(mask: Mask4, t: &V4, f: &V4) -> V4 {
        V4 {
            x: mask.select(t.x, f.x),
            y: mask.select(t.y, f.y),
            z: mask.select(t.z, f.z),
        }
    }
    /// Write vector `l` to `out[l]`: a transpose and three stores with AVX, otherwise one
    /// component at a time.
    #[inline(always)]
    pub(crate) fn store(&self, out: &mut [Vec3; LANES]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
        avx::transpose_out([self.x.0, self.y.0, self.z.0], out);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
        self.store_refs(out.each_mut());
    }
    /// Write vector `l` to `*out[l]`: a transpose and two stores a vector with AVX, otherwise
    /// one component at a time.
    #[inline(always)]
    pub(crate) fn store_refs(&self, out: [&mut Vec3; LANES]) {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
        avx::transpose_out_refs([self.x.0, self.y.0, self.z.0], out);
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
        {
            let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
            for (l, o) in out.into_iter().enumerate() {
                *o = Vec3::new(x[l], y[l], z[l]);
            }
        }
    }
    /// The sum of the four vectors.
    #[inline(always)]
    pub(crate) fn sum(&self) -> Vec3 {
        Vec3::new(self.x.sum(), self.y.sum(), self.z.sum())
    }
}

impl Add for V4 {
    type Output = V4;
    #[inline(always)]
    fn add(self, o: V4) -> V4 {
        V4 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V4 {
    type Output = V4;
    #[inline(always)]
    fn sub(self, o: V4) -> V4 {
        V4 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for V4 {
    type Output = V4;
    #[inline(always)]
    fn neg(self) -> V4 {
        V4 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl AddAssign for V4 {
    #[inline(always)]
    fn add_assign(&mut self, o: V4) {
        *self = *self + o;
    }
}

/// Moving four 3-vectors in and out of lanes with AVX shuffles (pure data movement: the same
/// bits as component-by-component copies).
#[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
mod avx {
    use super::{Vec3, LANES};
    use std::arch::x86_64::{
        __m256d, _mm256_blend_pd, _mm256_castpd256_pd128, _mm256_extractf128_pd,
        _mm256_maskload_pd, _mm256_permute2f128_pd, _mm256_set_epi64x, _mm256_storeu_pd,
        _mm256_unpackhi_pd, _mm256_unpacklo_pd, _mm_store_sd, _mm_storeu_pd,
    };
    use wide::f64x4;

    // `f64x4` is one `__m256d` in a build with AVX: the transmutes below only rename it.
    const _: () = assert!(std::mem::size_of::<f64x4>() == std::mem::size_of::<__m256d>());

    /// `[x, y, z]`: the first, second and third components of `v[0..4]` in lanes 0..4.
    #[inline(always)]
    pub(super) fn transpose_in(v: [&Vec3; LANES]) -> [f64x4; 3] {
        // SAFETY: AVX is enabled for the whole build (the cfg above). Each masked load reads
        // the three components of a live `Vec3` (contiguous `f64`s); the fourth lane is masked
        // off, so nothing past the vector is read.
        unsafe {
            let mask = _mm256_set_epi64x(0, -1, -1, -1);
            let [a, b, c, d] = v.map(|v| _mm256_maskload_pd(v.as_ptr(), mask));
            let ab_xz = _mm256_unpacklo_pd(a, b); // ax bx az bz
            let ab_y = _mm256_unpackhi_pd(a, b); // ay by 0 0
            let cd_xz = _mm256_unpacklo_pd(c, d);
            let cd_y = _mm256_unpackhi_pd(c, d);
            [
                _mm256_permute2f128_pd(ab_xz, cd_xz, 0x20),
                _mm256_permute2f128_pd(ab_y, cd_y, 0x20),
                _mm256_permute2f128_pd(ab_xz, cd_xz, 0x31),
            ]
            .map(|m| std::mem::transmute::<__m256d, f64x4>(m))
        }
    }

    /// Vector `l` of the lanes `[x, y, z]` written to `out[l]`.
    #[inline(always)]
    pub(super) fn transpose_out(lanes: [f64x4; 3], out: &mut [Vec3; LANES]) {
        // SAFETY: AVX is enabled for the whole build. `out` is four `Vec3`s, twelve contiguous
        // `f64`s: the three unaligned stores write exactly those.
        unsafe {
            let [x, y, z] = lanes.map(|l| std::mem::transmute::<f64x4, __m256d>(l));
            let xy_even = _mm256_unpacklo_pd(x, y); // x0 y0 x2 y2
            let yz_odd = _mm256_unpackhi_pd(y, z); // y1 z1 y3 z3
            let zx = _mm256_blend_pd(z, x, 0b1010); // z0 x1 z2 x3
            let p = out.as_mut_ptr() as *mut f64;
            _mm256_storeu_pd(p, _mm256_permute2f128_pd(xy_even, zx, 0x20));
            _mm256_storeu_pd(p.add(4), _mm256_blend_pd(yz_odd, xy_even, 0b1100));
            _mm256_storeu_pd(p.add(8), _mm256_permute2f128_pd(zx, yz_odd, 0x31));
        }
    }

    /// Vector `l` of the lanes `[x, y, z]` written to `*out[l]`.
    #[inline(always)]
    pub(super) fn transpose_out_refs(lanes: [f64x4; 3], out: [&mut Vec3; LANES]) {
        // SAFETY: AVX is enabled for the whole build. Each pair of stores writes the three
        // components of a live, exclusively borrowed `Vec3` (contiguous `f64`s), and nothing
        // past them.
        unsafe {
            let [x, y, z] = lanes.map(|l| std::mem::transmute::<f64x4, __m256d>(l));
            let xy_even = _mm256_unpacklo_pd(x, y); // x0 y0 x2 y2
            let xy_odd = _mm256_unpackhi_pd(x, y); // x1 y1 x3 y3
            let z_even = _mm256_unpacklo_pd(z, z); // z0 z0 z2 z2
            let z_odd = _mm256_unpackhi_pd(z, z); // z1 z1 z3 z3
            let vectors = [
                _mm256_permute2f128_pd(xy_even, z_even, 0x20), // x0 y0 z0 z0
                _mm256_permute2f128_pd(xy_odd, z_odd, 0x20),
                _mm256_permute2f128_pd(xy_even, z_even, 0x31),
                _mm256_permute2f128_pd(xy_odd, z_odd, 0x31),
            ];
            for (o, v) in out.into_iter().zip(vectors) {
                let p = o.as_mut_ptr();
                _mm_storeu_pd(p, _mm256_castpd256_pd128(v));
                _mm_store_sd(p.add(2), _mm256_extractf128_pd(v, 1));
            }
        }
    }
}

/// Permuting the lanes of one vector with AVX2 (pure data movement).
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
mod avx2 {
    use std::arch::x86_64::{__m256d, _mm256_permute4x64_pd};
    use wide::f64x4;

    /// Lane `l` of the result is lane `(P >> 2 l) & 3` of `v`.
    #[inline(always)]
    pub(super) fn permute<const P: i32>(v: f64x4) -> f64x4 {
        // SAFETY: AVX2 is enabled for the whole build (the cfg above); `f64x4` is one
        // `__m256d` in such a build, so the transmutes only rename it.
        unsafe {
            let v = std::mem::transmute::<f64x4, __m256d>(v);
            std::mem::transmute::<__m256d, f64x4>(_mm256_permute4x64_pd::<P>(v))
        }
    }
}

/// Four 3×3 matrices (any unit), one lane each, by rows.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct M4 {
    pub(crate) rows: [V4; 3],
}

impl M4 {
    /// All lanes `m`.
    #[inline(always)]
    pub(crate) fn splat(m: &Mat3) -> M4 {
        M4 {
            rows: [0, 1, 2].map(|r| V4 {
                x: F4::splat(m[(r, 0)]),
                y: F4::splat(m[(r, 1)]),
                z: F4::splat(m[(r, 2)]),
            }),
        }
    }
    /// Lane `l` is `m[l]`.
    #[inline(always)]
    pub(crate) fn from_matrices(m: &[Mat3; LANES]) -> M4 {
        M4 {
            rows: [0, 1, 2].map(|r| V4 {
                x: F4::new(m.map(|m| m[(r, 0)])),
                y: F4::new(m.map(|m| m[(r, 1)])),
                z: F4::new(m.map(|m| m[(r, 2)])),
            }),
        }
    }
    /// The matrix in lane `l`.
    #[inline(always)]
    pub(crate) fn lane(&self, l: usize) -> Mat3 {
        let [r0, r1, r2] = self.rows.map(|r| [r.x, r.y, r.z].map(|c| c.to_array()[l]));
        Mat3::new(
            r0[0], r0[1], r0[2], r1[0], r1[1], r1[2], r2[0], r2[1], r2[2],
        )
    }
    /// Column `c` (0, 1 or 2) of every lane.
    #[inline(always)]
    pub(crate) fn column(&self, c: usize) -> V4 {
        let [r0, r1, r2] = &self.rows;
        let pick = |r: &V4| [r.x, r.y, r.z][c];
        V4 {
            x: pick(r0),
            y: pick(r1),
            z: pick(r2),
        }
    }
    /// Lane-wise `mask ? t : f`.
    #[inline(always)]
    pub(crate) fn select(mask: Mask4, t: &M4, f: &M4) -> M4 {
        M4 {
            rows: [0, 1, 2].map(|r| V4::select(mask, &t.rows[r], &f.rows[r])),
        }
    }
    /// Every lane scaled by the lane's `s`.
    #[inline(always)]
    pub(crate) fn scale(&self, s: F4) -> M4 {
        M4 {
            rows: self.rows.map(|r| r.scale(s)),
        }
    }
    /// Lane-wise `self - o`.
    #[inline(always)]
    pub(crate) fn sub(&self, o: &M4) -> M4 {
        M4 {
            rows: [0, 1, 2].map(|r| self.rows[r] - o.rows[r]),
        }
    }
    /// Lane-wise `self + o`.
    #[inline(always)]
    pub(crate) fn add(&self, o: &M4) -> M4 {
        M4 {
            rows: [0, 1, 2].map(|r| self.rows[r] + o.rows[r]),
        }
    }
    /// Lane-wise Frobenius inner product `Σ_ab self_ab o_ab`, row by row.
    #[inline(always)]
    pub(crate) fn inner(&self, o: &M4) -> F4 {
        let [a0, a1, a2] = &self.rows;
        let [b0, b1, b2] = &o.rows;
        a0.dot(b0) + a1.dot(b1) + a2.dot(b2)
    }
    /// Lane-wise `self += a bᵀ`.
    #[inline(always)]
    pub(crate) fn add_outer(&mut self, a: &V4, b: &V4) {
        for (r, s) in self.rows.iter_mut().zip([a.x, a.y, a.z]) {
            *r = b.scale_add(s, r);
        }
    }
    /// Lane-wise `self v`.
    #[inline(always)]
    pub(crate) fn mul(&self, v: &V4) -> V4 {
        let [r0, r1, r2] = &self.rows;
        V4 {
            x: r0.dot(v),
            y: r1.dot(v),
            z: r2.dot(v),
        }
    }
    /// Lane-wise `self v - a`: each component `x - a` first, then the other two products
    /// added, each rounded once where the build has FMA.
    #[inline(always)]
    pub(crate) fn mul_sub(&self, v: &V4, a: &V4) -> V4 {
        let row = |r: &V4, a: F4| r.z.mul_add(v.z, r.y.mul_add(v.y, r.x.mul_sub(v.x, a)));
        let [r0, r1, r2] = &self.rows;
        V4 {
            x: row(r0, a.x),
            y: row(r1, a.y),
            z: row(r2, a.z),
        }
    }
    /// Lane-wise the matrix with columns `a`, `b`, `c`.
    #[inline(always)]
    pub(crate) fn from_columns(a: &V4, b: &V4, c: &V4) -> M4 {
        M4 {
            rows: [
                V4 {
                    x: a.x,
                    y: b.x,
                    z: c.x,
                },
                V4 {
                    x: a.y,
                    y: b.y,
                    z: c.y,
                },
                V4 {
                    x: a.z,
                    y: b.z,
                    z: c.z,
                },
            ],
        }
    }
    /// Lane-wise transpose.
    #[inline(always)]
    pub(crate) fn transpose(&self) -> M4 {
        M4::from_columns(&self.rows[0], &self.rows[1], &self.rows[2])
    }
    /// Lane-wise matrix product `self o`: row `a` is `Σ_k self_ak (row k of o)`.
    #[inline(always)]
    pub(crate) fn mul_mat(&self, o: &M4) -> M4 {
        let [o0, o1, o2] = &o.rows;
        M4 {
            rows: self
                .rows
                .map(|r| o2.scale_add(r.z, &o1.scale_add(r.y, &o0.scale(r.x)))),
        }
    }
    /// The sum of the four matrices.
    #[inline(always)]
    pub(crate) fn sum(&self) -> Mat3 {
        let [r0, r1, r2] = self.rows.map(|r| r.sum());
        Mat3::from_rows(&[r0.transpose(), r1.transpose(), r2.transpose()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_store_in_order_and_sum_in_a_fixed_order() {
        let v = V4 {
            x: F4::new([1.0, 2.0, 3.0, 4.0]),
            y: F4::new([5.0, 6.0, 7.0, 8.0]),
            z: F4::new([9.0, 10.0, 11.0, 12.0]),
        };
        let mut out = [Vec3::zeros(); LANES];
        v.store(&mut out);
        assert_eq!(out[1], Vec3::new(2.0, 6.0, 10.0));
        assert_eq!(out[3], Vec3::new(4.0, 8.0, 12.0));
        let a = F4::new([1e16, 1.0, -1e16, 1.0]);
        // Pairwise, each 1 is rounded away against 1e16: 0. Left to right would give 1.
        assert_eq!(a.sum(), 0.0);
        assert_eq!(a * F4::splat(2.0) - a + F4::default(), a);
    }

    /// Where the build targets FMA, the products that are added are rounded once: `(1 + ε)(1 - ε)
    /// - 1` is `-ε²` fused, 0 rounded twice. Elsewhere, twice (the module doc's contract).
    #[test]
    fn products_are_fused_exactly_where_the_build_has_fma() {
        let e = Real::EPSILON;
        let a = F4::splat(1.0 + e);
        let b = F4::splat(1.0 - e);
        let fused = cfg!(all(target_arch = "x86_64", target_feature = "fma"));
        let expected = if fused { -e * e } else { 0.0 };
        assert_eq!(a.mul_sub(b, F4::splat(1.0)).to_array(), [expected; LANES]);
        // The dot product: the first product -1 (exact), then (1 + ε)(1 - ε) added to it.
        let (zero, one) = (F4::splat(0.0), F4::splat(1.0));
        let v = V4 {
            x: one,
            y: a,
            z: zero,
        };
        let w = V4 {
            x: -one,
            y: b,
            z: zero,
        };
        assert_eq!(v.dot(&w).to_array(), [expected; LANES]);
    }

    /// Gathering by index and storing (to an array or through references) move every
    /// component to its place, bit for bit, the last vector of the field included (the loads
    /// must not read past it), and nothing beside a target is written.
    #[test]
    fn gathered_and_stored_vectors_keep_their_components() {
        let field: Vec<Vec3> = (0..7)
            .map(|k| Vec3::new(k as Real + 0.25, -(k as Real) - 0.5, 1e-300 * k as Real))
            .collect();
        let j = [6, 0, 3, 6];
        // SAFETY: every index is below 7.
        let v = unsafe { V4::gather_unchecked(&field, &j) };
        for (l, &k) in j.iter().enumerate() {
            let lane = |c: F4| c.to_array()[l];
            assert_eq!(
                Vec3::new(lane(v.x), lane(v.y), lane(v.z)),
                field[k as usize]
            );
        }
        let mut out = [Vec3::zeros(); LANES];
        v.store(&mut out);
        assert_eq!(out, j.map(|k| field[k as usize]));
        // Stored through references, the neighbours of each target untouched.
        let mut targets = [Vec3::repeat(7.0); 2 * LANES + 1];
        let [_, a, _, b, _, c, _, d, _] = &mut targets;
        v.store_refs([d, b, a, c]);
        let mut expected = [Vec3::repeat(7.0); 2 * LANES + 1];
        for (t, l) in [7, 3, 1, 5].into_iter().zip([0, 1, 2, 3]) {
            expected[t] = field[j[l] as usize];
        }
        assert_eq!(targets, expected);
    }
}
