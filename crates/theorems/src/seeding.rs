//! Deterministic seeding shared by the campaign runner and the strategies: chunk `k` of
//! property `name` under master seed `seed` draws from a ChaCha generator seeded with
//! `splitmix(seed, name, k)` ([`chunk_rng`]).
use proptest::test_runner::{RngAlgorithm, TestRng};

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator of chunk `chunk` of property `name` under master seed `seed`.
pub fn chunk_rng(seed: u64, name: &str, chunk: u64) -> TestRng {
    let mut h = splitmix(seed);
    for b in name.bytes() {
        h = splitmix(h ^ b as u64);
    }
    h = splitmix(h ^ chunk);
    let mut bytes = [0u8; 32];
    let mut s = h;
    for k in 0..4 {
        s = splitmix(s);
        bytes[8 * k..8 * k + 8].copy_from_slice(&s.to_le_bytes());
    }
    TestRng::from_seed(RngAlgorithm::ChaCha, &bytes)
}
