//! Seeded random numbers: one keyed stream for every stochastic path (solver rays, renderer
//! pixels, reference paths) and one tiny generator for test and benchmark inputs.
//!
//! Determinism (`shared/DESIGN.md`): a stream is keyed by `(seed, task, index)` — a shooter
//! and an element, a pixel, a path — never by a thread, so one thread and many give the same
//! numbers.

/// The SplitMix64 finaliser (Steele, Lea & Flood 2014) of `z + φ·2⁶⁴`: a strong 64-bit mix,
/// used to key streams and to hash.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(GOLDEN_GAMMA);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// SplitMix64's increment, ⌊2⁶⁴/φ⌉ (odd).
const GOLDEN_GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// Four uniform numbers in [0, 1) with 16 bits each from one hash of `key` and `index`: for
/// a caller that needs a few numbers per index and can afford neither a stream's set-up nor
/// its draws (the solver's one ray per receiver: two points, each within 1/65 536 of a side).
#[inline]
pub fn four_units(key: u64, index: u64) -> [f32; 4] {
    let bits = mix(key ^ index);
    [0, 16, 32, 48].map(|shift| (bits >> shift & 0xffff) as u32 as f32 / 65_536.0)
}

/// A SplitMix64 stream (period 2⁶⁴; passes BigCrush), keyed per task.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The stream that starts from `state` (mixed first, so nearby states give unrelated
    /// streams).
    pub fn from_state(state: u64) -> Self {
        Rng(mix(state))
    }

    /// The stream of one `(seed, task, index)` task: e.g. a shooter and a receiving element,
    /// or a render and a pixel.
    pub fn for_task(seed: u64, task: u64, index: u64) -> Self {
        Rng(mix(seed ^ mix(task ^ mix(index))))
    }

    /// 64 uniform bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GOLDEN_GAMMA);
        mix(self.0)
    }

    /// A uniform number in [0, 1) with 53 bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Two uniform numbers in [0, 1) with 24 bits each, from one draw.
    #[inline]
    pub fn next_f32_pair(&mut self) -> (f32, f32) {
        let bits = self.next_u64();
        let unit = |b: u64| (b & 0xff_ffff) as f32 / (1u32 << 24) as f32;
        (unit(bits >> 40), unit(bits >> 8))
    }
}

/// Marsaglia's xorshift64 (2003): tiny and fully reproducible, for the inputs of tests and
/// benchmarks (random triangles, segments, mutations), whose sequences must not change
/// between runs or versions. Not for estimates: use [`Rng`].
#[derive(Clone, Debug)]
pub struct XorShift64(u64);

impl XorShift64 {
    /// The generator from a seed (must not be 0: the state would stay 0).
    ///
    /// # Panics
    /// When `seed` is 0.
    pub fn new(seed: u64) -> Self {
        assert!(seed != 0, "xorshift64 needs a non-zero seed");
        XorShift64(seed)
    }

    /// The next 64 bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in [0, 1) with 53 bits.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [0, 1) with 24 bits.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform-ish in `0..n` (modulo bias below 2⁻³² for the small `n` it is used with; 0 when
    /// `n` is 0).
    #[inline]
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
}
