//! Taking memory without aborting. Rust's collections abort the process when
//! the system refuses an allocation, and on Linux the system rarely refuses:
//! it overcommits, and the out-of-memory killer ends the process later. So
//! what an input makes lumen hold (a file read, a film, instances, a part's
//! pixels) is counted first and checked against the memory this machine (or
//! its container) has free, then reserved with `try_reserve`; either failing
//! is an error that says how much was needed.

use std::fmt;

/// Memory that could not be had: what it was for, how many bytes, and how
/// many were free when that is known.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryError {
    /// What needed it, in words ("the film", "the file").
    pub what: String,
    /// Bytes needed.
    pub bytes: u64,
    /// Bytes free, when the system says.
    pub available: Option<u64>,
}

impl fmt::Display for MemoryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
        write!(
            f,
            "{} needs {:.2} GiB of memory",
            self.what,
            gib(self.bytes)
        )?;
        match self.available {
            Some(free) => write!(
                f,
                ", more than the {:.2} GiB this machine has free",
                gib(free)
            ),
            None => write!(f, ", which the system refused"),
        }
    }
}

impl std::error::Error for MemoryError {}

/// Bytes of memory this process can still take: the system's
/// `MemAvailable`, or less when a control group (a container, a Slurm job)
/// or a limit on the address space (`ulimit -v`) leaves less. `None` where
/// the system does not say (not Linux).
pub fn available() -> Option<u64> {
    let system = kib_field("/proc/meminfo", "MemAvailable:")?.saturating_mul(1024);
    Some(
        [cgroup_room(), address_space_room()]
            .into_iter()
            .flatten()
            .fold(system, u64::min),
    )
}

/// What a limit on the process's address space (`ulimit -v`, RLIMIT_AS)
/// leaves: the limit less the address space in use, if there is a limit.
fn address_space_room() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let limit = limits
        .lines()
        .find_map(|l| l.strip_prefix("Max address space"))?
        .split_whitespace()
        .next()?
        .parse::<u64>()
        .ok()?; // "unlimited": no limit
    let used_kib = kib_field("/proc/self/status", "VmSize:")?;
    Some(limit.saturating_sub(used_kib.saturating_mul(1024)))
}

/// The number of kilobytes on the line of `file` (a /proc file of
/// `Key:   1234 kB` lines) that starts with `key`.
fn kib_field(file: &str, key: &str) -> Option<u64> {
    std::fs::read_to_string(file)
        .ok()?
        .lines()
        .find_map(|l| l.strip_prefix(key))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()
}

/// What a cgroup v2 memory limit leaves: `memory.max - memory.current` of
/// this process's group, if it has a limit.
fn cgroup_room() -> Option<u64> {
    let group = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let rel = group.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(rel.trim_start_matches('/'));
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let max = read("memory.max")?.trim().parse::<u64>().ok()?; // "max": no limit
    let current = read("memory.current")?.trim().parse::<u64>().unwrap_or(0);
    Some(max.saturating_sub(current))
}

/// Checks that `bytes` more bytes can be had for `what`.
pub fn check(bytes: u64, what: &str) -> Result<(), MemoryError> {
    let fail = |available| MemoryError {
        what: what.to_string(),
        bytes,
        available,
    };
    if bytes > isize::MAX as u64 {
        return Err(fail(available()));
    }
    match available() {
        Some(free) if bytes > free => Err(fail(Some(free))),
        _ => Ok(()),
    }
}

/// An empty vector with room for `n` elements, checked (see [`check`]) and
/// reserved without aborting.
pub fn vec_for<T>(n: u64, what: &str) -> Result<Vec<T>, MemoryError> {
    let bytes = n.saturating_mul(std::mem::size_of::<T>() as u64);
    check(bytes, what)?;
    let mut v = Vec::new();
    let n = usize::try_from(n).map_err(|_| MemoryError {
        what: what.to_string(),
        bytes,
        available: None,
    })?;
    v.try_reserve_exact(n).map_err(|_| MemoryError {
        what: what.to_string(),
        bytes,
        available: None,
    })?;
    Ok(v)
}

/// A vector of `n` copies of `value`, taken as [`vec_for`] takes it.
pub fn filled<T: Clone>(n: u64, value: T, what: &str) -> Result<Vec<T>, MemoryError> {
    let mut v = vec_for(n, what)?;
    v.resize(n as usize, value);
    Ok(v)
}

/// Bytes of a huge page (x86-64, AArch64 with 4 KB pages): 2 MiB.
#[cfg(target_os = "linux")]
const HUGE_PAGE: usize = 2 << 20;

/// An empty vector with room for `n` elements, taken without aborting
/// (`None` if the allocator refuses), whose memory the system is asked to
/// back with huge pages where it can (Linux's transparent huge pages, in
/// their default "madvise" mode).
///
/// For data read at random all over, such as a texture: a 2048 × 2048
/// texture spans 4,096 pages of 4 KB, so nearly every lookup misses the
/// processor's table of page translations (the TLB); on 2 MB pages it
/// spans eight. The memory is taken when first written, as always; with
/// huge pages a fault maps 2 MB at once, so filling it faults 512 times
/// less often. Elsewhere, or where the system declines, the advice is
/// ignored and the vector is an ordinary one.
pub fn huge_vec<T>(n: usize) -> Option<Vec<T>> {
    let mut v: Vec<T> = Vec::new();
    v.try_reserve_exact(n).ok()?;
    advise_huge_pages(
        v.as_mut_ptr().cast(),
        n.saturating_mul(std::mem::size_of::<T>()),
    );
    Some(v)
}

/// Asks the system to back the whole 2 MB pages within `len` bytes from
/// `start` with huge pages.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
fn advise_huge_pages(start: *mut u8, len: usize) {
    let first = (start as usize).next_multiple_of(HUGE_PAGE);
    let end = (start as usize).saturating_add(len) / HUGE_PAGE * HUGE_PAGE;
    if end > first {
        // SAFETY: [first, end) lies within an allocation this process owns
        // (a vector's reserved capacity); madvise with MADV_HUGEPAGE
        // changes how pages are backed, never their content, and its
        // failure (a kernel without transparent huge pages) leaves the
        // memory as it was.
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_start: *mut u8, _len: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_page_vectors_hold_what_is_put_in_them_and_refuse_the_impossible() {
        // 8 MiB, over several huge pages whatever the allocation's start.
        let n = 1 << 20;
        let mut v: Vec<u64> = huge_vec(n).expect("8 MiB");
        assert!(v.is_empty() && v.capacity() >= n);
        v.extend((0..n as u64).map(|i| i.wrapping_mul(0x9e37_79b9_7f4a_7c15)));
        assert!(v
            .iter()
            .enumerate()
            .all(|(i, &x)| x == (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)));
        // A size no allocator grants is refused, not an abort.
        assert!(huge_vec::<u64>(usize::MAX / 4).is_none());
        // Small and empty ones are ordinary vectors.
        assert!(huge_vec::<u8>(0).is_some_and(|v| v.is_empty()));
        assert!(huge_vec::<u8>(100).is_some_and(|v| v.capacity() >= 100));
    }

    #[test]
    fn small_amounts_are_had_and_impossible_ones_refused() {
        let v: Vec<u64> = filled(1000, 7, "a test").unwrap();
        assert_eq!((v.len(), v[999]), (1000, 7));
        let e = vec_for::<u8>(1 << 62, "the film").unwrap_err();
        assert_eq!(e.bytes, 1 << 62);
        assert!(e.to_string().starts_with("the film needs"), "{e}");
        let e = vec_for::<[u64; 4]>(u64::MAX / 2, "x").unwrap_err();
        assert_eq!(e.bytes, u64::MAX);
        if let Some(free) = available() {
            assert!(free > 0);
            assert!(check(free + (1 << 30), "more than free").is_err());
        }
    }
}
