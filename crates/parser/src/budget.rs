//! One memory budget for everything a scene or an image asks rpbrt to hold.
//!
//! Input decides how much memory a run needs: a film's resolution, an
//! image's header, a mesh's element counts, a subdivision level, the number
//! of directives in a scene. A [`MemoryBudget`] is the limit those claims
//! are held against. Each place that allocates for input works out what it
//! is about to hold (after a header is read, before the data is) and
//! [`charge`](MemoryBudget::charge)s it; when the total would pass the
//! limit, the charge fails with an [`OverBudget`] error that the caller
//! locates (`scene.pbrt:3:1: this film needs 8.0 GiB; --max-memory is
//! 6.0 GiB`) instead of the process aborting when an allocation fails.
//!
//! Charges are estimates of the memory held for input, not a count of
//! every allocation: buffers whose size does not grow with the input
//! (thread stacks, per-thread scratch, tables) are not charged, which is
//! why the default limit ([`default_limit`]) leaves part of the machine's
//! memory out. The budget is shared (cloning shares it) and thread-safe:
//! imports parsed on other threads charge the same total.
//!
//! This module depends on nothing else in the crate; the crates above pass
//! a budget down (parser options, scene description, image readers) and
//! never read a global one.

use std::borrow::Cow;
use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// A limit on the memory input may claim, and what has been charged
/// against it so far. Clones share the total.
#[derive(Clone)]
pub struct MemoryBudget {
    inner: Arc<Inner>,
}

struct Inner {
    limit: u64,
    used: AtomicU64,
    /// A charge has failed: whoever reads on can stop.
    exhausted: AtomicBool,
    /// What messages call the limit: "--max-memory" when the user set or
    /// can set it with that flag.
    label: Cow<'static, str>,
}

impl fmt::Debug for MemoryBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MemoryBudget")
            .field("limit", &self.limit())
            .field("used", &self.used())
            .field("label", &self.inner.label)
            .finish()
    }
}

/// The default budget: [`default_limit`], called "the memory limit".
impl Default for MemoryBudget {
    fn default() -> Self {
        MemoryBudget::new(default_limit())
    }
}

impl MemoryBudget {
    /// A budget of `limit` bytes, nothing charged yet.
    pub fn new(limit: u64) -> Self {
        MemoryBudget::labelled(limit, "the memory limit")
    }

    /// A budget whose limit messages call `label` (say `"--max-memory"`,
    /// the flag that sets it).
    pub fn labelled(limit: u64, label: impl Into<Cow<'static, str>>) -> Self {
        MemoryBudget {
            inner: Arc::new(Inner {
                limit,
                used: AtomicU64::new(0),
                exhausted: AtomicBool::new(false),
                label: label.into(),
            }),
        }
    }

    /// A budget no charge can exceed (for tools and tests that bound
    /// memory otherwise).
    pub fn unlimited() -> Self {
        MemoryBudget::new(u64::MAX)
    }

    /// The limit, in bytes.
    pub fn limit(&self) -> u64 {
        self.inner.limit
    }

    /// What has been charged and not released, in bytes.
    pub fn used(&self) -> u64 {
        self.inner.used.load(Ordering::Relaxed)
    }

    /// Whether a charge or check has failed: the input does not fit, so
    /// readers can stop at the first error rather than report every
    /// directive after it.
    pub fn exhausted(&self) -> bool {
        self.inner.exhausted.load(Ordering::Relaxed)
    }

    /// What can still be charged, in bytes.
    pub fn available(&self) -> u64 {
        self.limit().saturating_sub(self.used())
    }

    /// Sets `bytes` aside for `what` ("this film", "the mesh in
    /// \"bunny.ply\""), or fails, charging nothing, when that would take
    /// the total past the limit.
    pub fn charge(&self, bytes: u64, what: &str) -> Result<(), OverBudget> {
        let used = &self.inner.used;
        let mut current = used.load(Ordering::Relaxed);
        loop {
            let total = current.saturating_add(bytes);
            if total > self.inner.limit {
                return Err(self.over(bytes, current, what));
            }
            match used.compare_exchange_weak(current, total, Ordering::Relaxed, Ordering::Relaxed) {
                Ok(_) => return Ok(()),
                Err(now) => current = now,
            }
        }
    }

    /// [`MemoryBudget::charge`], describing what asked only when the
    /// charge fails (a scene of a million directives charges a million
    /// times).
    pub fn charge_lazily(
        &self,
        bytes: u64,
        what: impl FnOnce() -> String,
    ) -> Result<(), OverBudget> {
        self.charge(bytes, "")
            .map_err(|e| OverBudget { what: what(), ..e })
    }

    /// Whether `bytes` more would fit, without charging them: for memory
    /// held only for a moment (a decoder's buffer that is converted and
    /// dropped).
    pub fn check(&self, bytes: u64, what: &str) -> Result<(), OverBudget> {
        let current = self.used();
        if current.saturating_add(bytes) > self.inner.limit {
            return Err(self.over(bytes, current, what));
        }
        Ok(())
    }

    /// Gives back `bytes` charged earlier (memory that was freed).
    pub fn release(&self, bytes: u64) {
        let _ = self
            .inner
            .used
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |u| {
                Some(u.saturating_sub(bytes))
            });
    }

    /// The error for something that was read until it passed what the
    /// budget had left (`more_than` bytes), its full size unknown.
    pub fn exceeded(&self, more_than: u64, what: &str) -> OverBudget {
        OverBudget {
            more: true,
            ..self.over(more_than, self.used(), what)
        }
    }

    fn over(&self, needed: u64, in_use: u64, what: &str) -> OverBudget {
        self.inner.exhausted.store(true, Ordering::Relaxed);
        OverBudget {
            what: what.to_string(),
            needed,
            more: false,
            in_use,
            limit: self.inner.limit,
            label: self.inner.label.to_string(),
        }
    }
}

/// A charge that would pass the budget's limit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverBudget {
    /// What asked ("this film").
    pub what: String,
    /// The bytes it needs.
    pub needed: u64,
    /// It needs more than `needed` (its size was not known in advance).
    pub more: bool,
    /// The bytes charged before it.
    pub in_use: u64,
    /// The limit.
    pub limit: u64,
    /// What the limit is called ("--max-memory").
    pub label: String,
}

impl fmt::Display for OverBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let more = if self.more { "more than " } else { "" };
        write!(f, "{} needs {more}{}", self.what, format_bytes(self.needed))?;
        // What is in use matters only when the claim alone would fit.
        if self.needed <= self.limit && self.in_use > 0 {
            write!(f, " with {} in use already", format_bytes(self.in_use))?;
        }
        write!(f, "; {} is {}", self.label, format_bytes(self.limit))
    }
}

impl std::error::Error for OverBudget {}

/// What a heap allocation of `bytes` takes, for estimates: the bytes
/// rounded up to the allocator's 16-byte granules, plus one granule of
/// bookkeeping (nothing for an empty allocation, which takes none).
pub fn heap(bytes: usize) -> usize {
    if bytes == 0 {
        0
    } else {
        bytes.div_ceil(16) * 16 + 16
    }
}

/// What an element of type `T` of a growing vector takes, for estimates:
/// its size twice over, since a vector's capacity runs up to twice its
/// length (and while it grows, the old and new buffers exist together).
pub fn vec_element<T>() -> usize {
    2 * std::mem::size_of::<T>()
}

/// `bytes` for people: "512 bytes", "1.5 KiB", "8.0 GiB" (powers of 1024).
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if bytes < 1024 {
        return format!("{bytes} bytes");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    // One decimal; a value that rounds up to 1024.0 takes the next unit.
    if (value * 10.0).round() / 10.0 >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.1} {}", UNITS[unit])
}

/// Reads a size as given on a command line: a number of bytes, optionally
/// with a fraction and a binary unit: `K`, `M`, `G`, `T` (each 1024 times
/// the one before), in either case and optionally followed by `B` or `iB`
/// (`6G`, `6GiB`, `1.5g` and `512MB` all work; `GB` means GiB here).
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let unit = unit.trim();
    let scale: u64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        _ => {
            return Err(format!(
                "\"{text}\" is not a size (expected a number with an optional unit K, M, G or T, e.g. 6G)"
            ))
        }
    };
    let value: f64 = number
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
        .ok_or_else(|| {
            format!("\"{text}\" is not a size (expected a number with an optional unit K, M, G or T, e.g. 6G)")
        })?;
    let bytes = value * scale as f64;
    if bytes >= u64::MAX as f64 {
        return Err(format!("\"{text}\" is too large"));
    }
    Ok(bytes.round() as u64)
}

/// The memory this machine lets the process have, in bytes: the least of
/// its physical memory (`MemTotal` in `/proc/meminfo`), its control
/// group's limit (`/sys/fs/cgroup/memory.max`, cgroup v2) and half its
/// address-space limit (`ulimit -v`, `prlimit --as`; halved because
/// address space also goes to thread stacks, allocator arenas and the
/// program's code). `None` where none of these can be read.
pub fn machine_memory() -> Option<u64> {
    let physical = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| meminfo_total(&s));
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    let address_space = std::fs::read_to_string("/proc/self/limits")
        .ok()
        .and_then(|s| address_space_limit(&s))
        .map(|l| l / 2);
    [physical, cgroup, address_space]
        .into_iter()
        .flatten()
        .min()
}

/// The limit used when the machine's memory cannot be read: 8 GiB.
pub const FALLBACK_LIMIT: u64 = 8 << 30;

/// The default limit: three quarters of [`machine_memory`] (the rest is
/// left for what is not charged: the program, threads, acceleration
/// structures' build buffers, the system), or [`FALLBACK_LIMIT`]. Worked
/// out once per process.
pub fn default_limit() -> u64 {
    static LIMIT: OnceLock<u64> = OnceLock::new();
    *LIMIT.get_or_init(|| match machine_memory() {
        Some(m) => m / 4 * 3,
        None => FALLBACK_LIMIT,
    })
}

/// `MemTotal` of `/proc/meminfo` text, in bytes.
fn meminfo_total(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line.split_whitespace().skip(1);
    let n: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => n.checked_mul(1024),
        None => Some(n),
        Some(_) => None,
    }
}

/// The soft address-space limit of `/proc/self/limits` text, in bytes
/// (`None` when unlimited).
fn address_space_limit(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    let soft = line["Max address space".len()..]
        .split_whitespace()
        .next()?;
    soft.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charges_add_up_until_the_limit() {
        let b = MemoryBudget::new(1000);
        assert!(b.charge(600, "this").is_ok());
        let shared = b.clone();
        let e = shared.charge(500, "that").unwrap_err();
        assert_eq!((e.needed, e.in_use, e.limit), (500, 600, 1000));
        // A failed charge takes nothing.
        assert_eq!(b.used(), 600);
        assert!(b.check(400, "x").is_ok());
        assert!(b.check(401, "x").is_err());
        assert_eq!(b.used(), 600);
        b.release(600);
        assert!(b.charge(1000, "all").is_ok());
        assert_eq!(b.available(), 0);
        assert!(MemoryBudget::unlimited().charge(u64::MAX, "all").is_ok());
        assert!(b.exhausted() && !MemoryBudget::new(1).exhausted());
    }

    #[test]
    fn the_message_names_the_claim_and_the_limit() {
        let b = MemoryBudget::labelled(6 << 30, "--max-memory");
        let e = b.charge(8 << 30, "this film").unwrap_err();
        assert_eq!(
            e.to_string(),
            "this film needs 8.0 GiB; --max-memory is 6.0 GiB"
        );
        b.charge(5 << 30, "a mesh").unwrap();
        let e = b.charge(2 << 30, "this film").unwrap_err();
        assert_eq!(
            e.to_string(),
            "this film needs 2.0 GiB with 5.0 GiB in use already; --max-memory is 6.0 GiB"
        );
        let e = MemoryBudget::new(100).charge(200, "it").unwrap_err();
        assert_eq!(
            e.to_string(),
            "it needs 200 bytes; the memory limit is 100 bytes"
        );
    }

    #[test]
    fn sizes_read_and_print() {
        assert_eq!(parse_size("6G"), Ok(6 << 30));
        assert_eq!(parse_size("6GiB"), Ok(6 << 30));
        assert_eq!(parse_size("6 gb"), Ok(6 << 30));
        assert_eq!(parse_size("1.5g"), Ok(3 << 29));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("64k"), Ok(64 << 10));
        assert_eq!(parse_size("2T"), Ok(2 << 40));
        assert_eq!(parse_size("1000"), Ok(1000));
        for bad in ["", "G", "-1G", "6X", "1e3", "lots", "99999999999T"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert_eq!(format_bytes(0), "0 bytes");
        assert_eq!(format_bytes(1023), "1023 bytes");
        assert_eq!(format_bytes(1536), "1.5 KiB");
        assert_eq!(format_bytes(8 << 30), "8.0 GiB");
        assert_eq!(format_bytes((1 << 30) - 1), "1.0 GiB");
        assert_eq!(format_bytes(u64::MAX), "16.0 EiB");
    }

    #[test]
    fn machine_memory_is_read_from_proc_text() {
        assert_eq!(
            meminfo_total("MemTotal:       24528356 kB\nMemFree: 1 kB\n"),
            Some(24528356 * 1024)
        );
        assert_eq!(meminfo_total("MemFree: 1 kB\n"), None);
        let limits = "Limit                     Soft Limit           Hard Limit           Units     \n\
                      Max address space         4294967296           unlimited            bytes     \n";
        assert_eq!(address_space_limit(limits), Some(4 << 30));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(address_space_limit(unlimited), None);
        assert!(default_limit() > 0);
    }
}
