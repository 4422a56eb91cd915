//! Exact dyadic arithmetic for the tests: `m 2^e` with an `i128` mantissa, enough for sums and
//! products of a few `f64` of moderate exponent range (every operation panics rather than
//! overflow, so a test cannot pass on a wrapped value). And a seeded generator.

use std::cmp::Ordering;

/// The exact value `m 2^e` (normalised: `m` odd or zero).
#[derive(Debug, Clone, Copy)]
pub struct Dyadic {
    m: i128,
    e: i32,
}

impl Dyadic {
    pub fn zero() -> Self {
        Self { m: 0, e: 0 }
    }

    fn norm(mut m: i128, mut e: i32) -> Self {
        if m == 0 {
            return Self::zero();
        }
        let tz = m.trailing_zeros();
        m >>= tz;
        e += tz as i32;
        Self { m, e }
    }

    /// The exact value of a finite `f64`.
    pub fn of(x: f64) -> Self {
        assert!(x.is_finite(), "{x}");
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let frac = (bits & ((1u64 << 52) - 1)) as i128;
        let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | (1i128 << 52), exp - 1075) };
        Self::norm(if bits >> 63 == 1 { -m } else { m }, e)
    }

    /// Both mantissas at the smaller exponent.
    fn aligned(self, o: Self) -> (i128, i128, i32) {
        if self.m == 0 {
            return (0, o.m, o.e);
        }
        if o.m == 0 {
            return (self.m, 0, self.e);
        }
        let e = self.e.min(o.e);
        let shift = |m: i128, k: i32| {
            assert!((0..=125).contains(&k), "exponent spread {k} too large for the test range");
            m.checked_mul(1i128 << k).expect("mantissa overflow: test range too wide")
        };
        (shift(self.m, self.e - e), shift(o.m, o.e - e), e)
    }

    pub fn add(self, o: Self) -> Self {
        let (a, b, e) = self.aligned(o);
        Self::norm(a.checked_add(b).expect("overflow"), e)
    }

    pub fn sub(self, o: Self) -> Self {
        self.add(Self { m: -o.m, e: o.e })
    }

    pub fn mul(self, o: Self) -> Self {
        Self::norm(self.m.checked_mul(o.m).expect("overflow"), self.e + o.e)
    }

    pub fn abs(self) -> Self {
        Self { m: self.m.abs(), e: self.e }
    }

    /// `self 2^k`.
    pub fn shl(self, k: i32) -> Self {
        if self.m == 0 {
            self
        } else {
            Self { m: self.m, e: self.e + k }
        }
    }

    pub fn cmp(self, o: Self) -> Ordering {
        let (a, b, _) = self.aligned(o);
        a.cmp(&b)
    }

    pub fn le(self, o: Self) -> bool {
        self.cmp(o) != Ordering::Greater
    }

    pub fn eq(self, o: Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}

/// SplitMix64 (seeded, no dependency).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// A random float with a `bits`-bit mantissa (leading bit set), binary exponent in
    /// `[emin, emax]` and random sign.
    pub fn float_bits(&mut self, bits: u32, emin: i32, emax: i32) -> f64 {
        let m = (self.next_u64() >> (64 - bits)) | (1u64 << (bits - 1));
        let e = emin + (self.next_u64() % (emax - emin + 1) as u64) as i32;
        let x = m as f64 * 2f64.powi(e - bits as i32 + 1);
        if self.next_u64() & 1 == 1 {
            -x
        } else {
            x
        }
    }

    /// A random normal float (53-bit mantissa), binary exponent in `[emin, emax]`, random sign.
    pub fn float(&mut self, emin: i32, emax: i32) -> f64 {
        self.float_bits(53, emin, emax)
    }
}
