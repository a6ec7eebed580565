//! Values per cable (tensions, reel speeds, unstrained lengths) for m = 2 … [`MAX_CABLES`]
//! cables, held inline so that a right-hand side passes them without allocating, and the
//! cable's number as the field writes it (cable 1, 2, …).

use std::fmt;
use std::ops::{Deref, DerefMut};

/// Most cables a robot has (CoGiRo and IPAnema: 8).
pub const MAX_CABLES: usize = 8;

/// One value per cable [unit of the quantity], cable 1 first.
#[derive(Clone, Copy, PartialEq, Default)]
pub struct PerCable {
    values: [f64; MAX_CABLES],
    len: usize,
}

/// The commanded tensions T_1 … T_m [N].
pub type Tensions = PerCable;

impl PerCable {
    /// `m` zeros.
    pub fn zeros(m: usize) -> Self {
        assert!(m <= MAX_CABLES, "{m} cables: at most {MAX_CABLES}");
        Self {
            values: [0.0; MAX_CABLES],
            len: m,
        }
    }

    /// The values of `slice`, one per cable.
    pub fn from_slice(slice: &[f64]) -> Self {
        let mut v = Self::zeros(slice.len());
        v.values[..slice.len()].copy_from_slice(slice);
        v
    }

    /// `f(i)` for cables i = 0 … m − 1, in that order.
    pub fn from_fn(m: usize, mut f: impl FnMut(usize) -> f64) -> Self {
        assert!(m <= MAX_CABLES, "{m} cables: at most {MAX_CABLES}");
        // As one array expression, not element stores into zeros: a short closure then fills
        // vector registers, and the copy that follows does not wait on narrow stores (a
        // store-forwarding stall was a fifth of the one-redundancy QP).
        Self {
            values: std::array::from_fn(|i| if i < m { f(i) } else { 0.0 }),
            len: m,
        }
    }

    /// The values of the two cables of a planar robot.
    pub fn pair(values: [f64; 2]) -> Self {
        Self::from_slice(&values)
    }

    /// Each value mapped by `f`.
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Self {
        let mut v = *self;
        v.iter_mut().for_each(|x| *x = f(*x));
        v
    }

    /// Σ_i self_i · other_i (e.g. the reels' power Σ T_i v_reel,i), summed from cable 1.
    pub fn dot(&self, other: &PerCable) -> f64 {
        let mut pairs = self.iter().zip(other.iter());
        let Some((a, b)) = pairs.next() else {
            return 0.0;
        };
        pairs.fold(a * b, |sum, (a, b)| sum + a * b)
    }
}

impl Deref for PerCable {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

impl DerefMut for PerCable {
    fn deref_mut(&mut self) -> &mut [f64] {
        &mut self.values[..self.len]
    }
}

impl serde::Serialize for PerCable {
    /// As a list, cable 1 first (what `[f64; 2]` wrote for the planar robot).
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

impl fmt::Debug for PerCable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// A cable of the robot: index 0 … m − 1 in arrays, written 1 … m (T1, cable 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CableId(pub usize);

impl CableId {
    /// The cable numbered `number` (1-based).
    pub fn number(number: usize) -> Self {
        Self(number - 1)
    }

    /// Its index in per-cable arrays.
    pub fn index(self) -> usize {
        self.0
    }

    /// Cables 1 … m.
    pub fn all(m: usize) -> impl Iterator<Item = CableId> {
        (0..m).map(CableId)
    }
}

impl fmt::Display for CableId {
    /// The cable's number, 1-based.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0 + 1)
    }
}
