//! A render's stop: asked for from outside (Ctrl-C, SIGTERM, a time limit)
//! and looked at from inside the render loops, before every few pixels and
//! every few hundred bounces, so that a row of endless paths (a white fog
//! at a great depth) ends in moments rather than after the grace period a
//! job engine gives after SIGTERM.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether to stop, remembered once it is `true`.
pub struct Halt<'a> {
    halted: AtomicBool,
    should_stop: &'a (dyn Fn() -> bool + Sync),
}

impl<'a> Halt<'a> {
    /// A stop that asks `should_stop` whenever it is looked at, until it
    /// answers `true`.
    pub fn new(should_stop: &'a (dyn Fn() -> bool + Sync)) -> Self {
        Self {
            halted: AtomicBool::new(false),
            should_stop,
        }
    }

    /// A stop that never comes.
    pub fn never() -> Halt<'static> {
        Halt::new(&|| false)
    }

    /// Whether to stop: `true` from the first time `should_stop` said so.
    /// The render loops ask as they go, on their own threads, so that no
    /// thread needs to watch for them.
    #[inline]
    pub fn asked(&self) -> bool {
        if self.halted.load(Ordering::Relaxed) {
            return true;
        }
        let stop = (self.should_stop)();
        if stop {
            self.halted.store(true, Ordering::Relaxed);
        }
        stop
    }

    /// Whether a look before now found that the render is to stop (so
    /// that some of its work was left undone), without asking again.
    pub fn halted(&self) -> bool {
        self.halted.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU32;

    #[test]
    fn a_stop_once_asked_for_stays_and_is_not_asked_again() {
        let asks = AtomicU32::new(0);
        let should_stop = || asks.fetch_add(1, Ordering::Relaxed) >= 2;
        let halt = Halt::new(&should_stop);
        assert!(!halt.asked() && !halt.asked() && !halt.halted());
        assert!(halt.asked() && halt.halted());
        assert!(halt.asked());
        assert_eq!(asks.load(Ordering::Relaxed), 3);
        assert!(!Halt::never().asked());
    }
}
