//! A fast hasher for small keys the program makes itself: the rule
//! tables' and the grid cells the placeability searches visit.
//!
//! Loading a rule file turns every rule and generates the unseen ones,
//! checking each turned rule against the ones already made: hundreds of
//! thousands of look-ups of keys a few words long. The standard hasher
//! (SipHash, made to resist chosen keys from outside) costs more than the
//! rest of the look-up; these keys come from the program itself, so a
//! multiply-and-rotate hash (the one rustc uses for its own tables) does.
//! It is deterministic, and nothing iterates these tables, so no output
//! depends on it.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// A multiply-and-rotate hasher for small, trusted keys.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct KeyHasher(u64);

const K: u64 = 0xf135_7aea_2e62_a9c5;

impl KeyHasher {
    #[inline]
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(K);
    }
}

impl Hasher for KeyHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.add(u64::from_le_bytes(c.try_into().expect("chunk of 8")));
        }
        for &b in chunks.remainder() {
            self.add(u64::from(b));
        }
    }

    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u16(&mut self, i: u16) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }

    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }

    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A map keyed by small, trusted keys.
pub(crate) type KeyMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// A set of small, trusted keys.
pub(crate) type KeySet<K> = HashSet<K, BuildHasherDefault<KeyHasher>>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_keys_hash_alike_and_sets_work() {
        let mut s: KeySet<(u8, i32, (i32, i32))> = KeySet::default();
        for a in 0..20u8 {
            for b in -10..10 {
                assert!(s.insert((a, b, (b, -b))));
            }
        }
        assert_eq!(s.len(), 400);
        assert!(s.contains(&(3, -4, (-4, 4))));
        assert!(!s.contains(&(3, -4, (4, 4))));
    }
}
