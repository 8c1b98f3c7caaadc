//! How much memory a solve needs and how much this process can still allocate: the lowest
//! floor of the crate (it imports nothing of it), used by the SOLVE step, the adaptive loop, the
//! study runner and the mesh readers alike.

/// Peak memory of one solve with `ndof` unknowns, in bytes: 64 MiB + 2 KiB per unknown.
///
/// Fitted to the peak resident set of `signorini solve` (`/usr/bin/time -v`, rustc 1.95, faer
/// 0.24) on structured meshes: 1.62, 1.53, 1.59, 1.64 and 1.67 KiB per unknown at 33 282,
/// 132 098, 526 338, 1 182 722 and 2 101 250 unknowns (Examples 7.1 and 7.2 alike). The sparse
/// Cholesky factor grows slightly faster than linearly; 2 KiB per unknown keeps a margin of at
/// least 20 % over every measurement.
pub fn memory_estimate(ndof: f64) -> f64 {
    64.0 * MIB + 2048.0 * ndof
}

const MIB: f64 = 1024.0 * 1024.0;

/// Memory this process can still allocate, in bytes: the machine's memory available without
/// swapping (`MemAvailable` in `/proc/meminfo`), and, where the process's address space is
/// limited (`ulimit -v`, `prlimit --as`: "Max address space" in `/proc/self/limits`), no more
/// than what that limit leaves above the current virtual size (`/proc/self/statm`); `None`
/// where `/proc/meminfo` does not exist.
pub fn available_memory() -> Option<f64> {
    available().map(|a| a.bytes)
}

/// [`available_memory`] and which of the two bounds it is.
#[derive(Clone, Copy, Debug)]
pub struct Available {
    pub bytes: f64,
    /// The address-space limit, not the machine, is the bound.
    pub by_address_space: bool,
    /// The process's address-space limit and virtual size, where it has a limit.
    pub address_space: Option<AddressSpace>,
}

/// An address-space limit (`ulimit -v`, `prlimit --as`) and how much of it the process uses.
#[derive(Clone, Copy, Debug)]
pub struct AddressSpace {
    /// The soft limit (RLIMIT_AS, `getrlimit`), in bytes.
    pub limit: f64,
    /// The process's virtual size (`/proc/self/statm`), in bytes.
    pub in_use: f64,
}

impl AddressSpace {
    /// What the limit leaves above the virtual size.
    pub fn left(&self) -> f64 {
        (self.limit - self.in_use).max(0.0)
    }
}

pub fn available() -> Option<Available> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let machine = line.split_whitespace().nth(1)?.parse::<f64>().ok()? * 1024.0;
    let address_space = address_space();
    Some(match address_space {
        Some(space) if space.left() < machine => Available { bytes: space.left(), by_address_space: true, address_space },
        _ => Available { bytes: machine, by_address_space: false, address_space },
    })
}

/// The address-space limit's soft value and the current virtual size, if there is a limit.
fn address_space() -> Option<AddressSpace> {
    let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes the struct it is given, nothing else
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0 || lim.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: f64 = statm.split_whitespace().next()?.parse().ok()?;
    // SAFETY: sysconf only reads a constant of the system
    let page = match unsafe { libc::sysconf(libc::_SC_PAGESIZE) } {
        p if p > 0 => p as f64,
        _ => 4096.0,
    };
    Some(AddressSpace { limit: lim.rlim_cur as f64, in_use: pages * page })
}

/// Address space the solver's threads reserve beyond what [`memory_estimate`] counts (which is
/// resident memory), in bytes: an address-space limit counts it all, whether touched or not.
/// Per worker thread of the pool (`rayon::current_num_threads`): a glibc malloc arena (64 MiB
/// reserved on 64-bit Linux) and the thread's stack (2 MiB, Rust's default); per worker and the
/// main thread: the packing buffer of the dense products (faer through private-gemm-x86:
/// twice the largest CPU cache, allocated on a thread's first product, kept, and allocated
/// infallibly, so a failure there aborts the process). Threads that have run hold theirs inside
/// the process's virtual size from then on, so a check counts only what is still to come
/// ([`reserve_to_come`]). Measured (`prlimit --as`, ex71 on structured:4, 32 MiB L3): the solve
/// needs 220, 356 and 603 MB of address space with 1, 2 and 4 threads.
pub fn thread_reserve() -> f64 {
    let workers = rayon::current_num_threads() as f64;
    workers * (64.0 + 2.0) * MIB + (workers + 1.0) * 2.0 * largest_cache()
}

/// The process's virtual size at its first memory check under an address-space limit
/// ([`reserve_to_come`]).
static FIRST_IN_USE: std::sync::OnceLock<f64> = std::sync::OnceLock::new();

/// The part of [`thread_reserve`] not yet inside the virtual size `in_use`: the reserve less
/// what the virtual size has grown since this process's first check (which the command line
/// makes before any solve), so that the reserve is counted once per process, not again at
/// every level of an adaptive loop on top of a virtual size that already holds it. Growth of
/// another kind (the meshes and solutions a loop keeps) is taken for the reserve too: a level
/// whose threads have not run yet could be let through by that much, which the loop's kept
/// data, a few KiB per unknown of the levels solved, keeps far below the reserve while the
/// threads first run on the smallest levels. Returns (the reserve, what is still to come).
fn reserve_to_come(in_use: f64) -> (f64, f64) {
    let reserve = thread_reserve();
    let first = *FIRST_IN_USE.get_or_init(|| in_use);
    (reserve, (first + reserve - in_use).clamp(0.0, reserve))
}

/// The largest cache of CPU 0 in bytes (`/sys/devices/system/cpu/cpu0/cache/index*/size`), or
/// 32 MiB where that cannot be read.
fn largest_cache() -> f64 {
    let sizes = (0..8).filter_map(|i| std::fs::read_to_string(format!("/sys/devices/system/cpu/cpu0/cache/index{i}/size")).ok());
    let bytes = sizes.filter_map(|s| {
        let s = s.trim();
        let (digits, unit) = s.split_at(s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len()));
        let scale = match unit {
            "" => 1.0,
            "K" => 1024.0,
            "M" => MIB,
            _ => return None,
        };
        digits.parse::<f64>().ok().map(|d| d * scale)
    });
    bytes.fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b)))).unwrap_or(32.0 * MIB)
}

/// Where the machine's available memory is unknown (no `/proc/meminfo`), solves whose estimate
/// exceeds this (1 TiB) are refused all the same.
pub const UNKNOWN_MEMORY_LIMIT: f64 = 1024.0 * 1024.0 * MIB;

/// A solve that would not fit in memory.
#[derive(Debug, thiserror::Error)]
#[error("{what} has {ndof:.0} unknowns: solving needs about {} (estimate: {basis}), but {}", apart(*.needed, .available.map_or(0.0, |a| a.bytes))[0], match .available {
    Some(a) if a.by_address_space => format!("this process's address-space limit (ulimit -v) leaves {}{}", apart(*.needed, a.bytes)[1], a.address_space.map_or(String::new(), |s| format!(" (the limit {} less the {} this process uses)", human_bytes(s.limit), human_bytes(s.in_use)))),
    Some(a) => format!("this machine has {} available (MemAvailable in /proc/meminfo)", apart(*.needed, a.bytes)[1]),
    None => format!("this machine's available memory is unknown (no /proc/meminfo) and more than {} is refused", human_bytes(UNKNOWN_MEMORY_LIMIT)),
})]
pub struct MemoryError {
    pub what: String,
    pub ndof: f64,
    pub needed: f64,
    /// how `needed` was estimated
    pub basis: String,
    pub available: Option<Available>,
}

/// `a` and `b` as [`human_bytes`], with as many decimals (up to 4) as it takes for two
/// different sizes to read differently (never "needs about 1.7 GiB ... leaves 1.7 GiB").
fn apart(a: f64, b: f64) -> [String; 2] {
    let mut pair = [human_bytes(a), human_bytes(b)];
    for decimals in 2..=4 {
        if pair[0] != pair[1] || a == b {
            break;
        }
        pair = [a, b].map(|v| human_bytes_to(v, decimals));
    }
    pair
}

/// Refuse a solve with `ndof` unknowns before allocating anything, if its memory estimate exceeds
/// the machine's available memory (or [`UNKNOWN_MEMORY_LIMIT`] where that is unknown).
pub fn check_memory(what: &str, ndof: f64) -> Result<(), MemoryError> {
    check_memory_measured(what, ndof, None)
}

/// [`check_memory`] for a solve whose size a measured one predicts (the next level of an
/// adaptive loop, or a stored level solved again): `measured` is (unknowns, peak resident bytes)
/// of that solve. See [`level_estimate`].
pub fn check_memory_measured(what: &str, ndof: f64, measured: Option<(f64, f64)>) -> Result<(), MemoryError> {
    let available = available();
    let (mut needed, mut basis) = level_estimate(ndof, measured, available.is_some_and(|a| !a.by_address_space));
    // asked at every check under a limit, so that the first one sets where the reserve starts
    if let Some(space) = available.and_then(|a| a.address_space) {
        let (reserve, to_come) = reserve_to_come(space.in_use);
        if available.is_some_and(|a| a.by_address_space) {
            needed += to_come;
            basis += &reserve_basis(reserve, to_come, space.in_use);
        }
    }
    if needed > available.map_or(UNKNOWN_MEMORY_LIMIT, |a| a.bytes) {
        return Err(MemoryError { what: what.to_string(), ndof, needed, basis, available });
    }
    Ok(())
}

/// What a check counted of the threads' reserve ([`reserve_to_come`]), for the estimate's
/// basis: the reserve dwarfs a small level's own need, so its parts are named.
fn reserve_basis(reserve: f64, to_come: f64, in_use: f64) -> String {
    let workers = rayon::current_num_threads();
    let parts = format!(
        "per each of {workers} worker(s) a 64 MiB malloc arena and a 2 MiB stack, and per worker and the main thread twice the CPU's largest cache ({}) for the dense products' packing buffer; fewer threads, RAYON_NUM_THREADS, reserve less",
        human_bytes(largest_cache())
    );
    if to_come >= reserve {
        return format!(
            ", + {} of address space the threads reserve whatever the size, counted once per process ({parts})",
            human_bytes(reserve)
        );
    }
    format!(
        ", + {} still to come of the {} of address space the threads reserve whatever the size ({parts}); the rest is counted once, inside the {} this process already uses",
        human_bytes(to_come),
        human_bytes(reserve),
        human_bytes(in_use)
    )
}

/// Growth margin on a measured peak scaled to more unknowns.
const MEASURED_MARGIN: f64 = 1.25;

/// The memory a solve of `ndof` unknowns needs, and how it was estimated: [`memory_estimate`],
/// or, where the previous solve's peak resident set was measured (`measured`: its unknowns and
/// peak bytes) and the bound is the machine's memory (`resident_bound`; not an address-space
/// limit, which counts virtual memory that a resident peak does not see), that peak scaled
/// linearly to `ndof` with a 25% margin if it is smaller. The per-unknown estimate is fitted to
/// structured meshes (1.5-1.7 KiB per unknown); on meshes graded by adaptive refinement the
/// factor fills less (Example 7.1 refined with eta_5 as written peaked at 1.0 KiB per unknown at
/// 8.5e6 unknowns), and the estimate alone refused a level of 1.2e7 unknowns that fits.
pub fn level_estimate(ndof: f64, measured: Option<(f64, f64)>, resident_bound: bool) -> (f64, String) {
    let coarse = (memory_estimate(ndof), "64 MiB + 2 KiB per unknown".to_string());
    match measured {
        Some((n0, peak)) if resident_bound && n0 > 0.0 && peak > 0.0 => {
            let scaled = MEASURED_MARGIN * peak * (ndof / n0).max(1.0);
            if scaled < coarse.0 {
                (
                    scaled,
                    format!("{MEASURED_MARGIN} x the previous level's peak {} at {n0:.0} unknowns, scaled to these", human_bytes(peak)),
                )
            } else {
                coarse
            }
        }
        _ => coarse,
    }
}

/// Bytes in binary units: "3.4 GiB".
pub fn human_bytes(b: f64) -> String {
    human_bytes_to(b, 1)
}

/// [`human_bytes`] with `decimals` decimals.
fn human_bytes_to(b: f64, decimals: usize) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = b;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < units.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 { format!("{v:.0} B") } else { format!("{v:.decimals$} {}", units[u]) }
}

/// Reset this process's peak resident set (Linux: writing 5 to `/proc/self/clear_refs` sets
/// `VmHWM` to the current resident set), so that [`peak_resident`] measures from here; false
/// where that is not possible (then [`peak_resident`] is the peak since the process started).
pub fn reset_peak_resident() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// This process's peak resident set in bytes (`VmHWM` in `/proc/self/status`), or None where it
/// cannot be read.
pub fn peak_resident() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.split_whitespace().nth(1)?.parse::<f64>().ok()? * 1024.0)
}

#[cfg(test)]
mod tests {
    #[test]
    fn two_different_sizes_read_differently() {
        let g = 1024.0 * 1024.0 * 1024.0;
        assert_eq!(super::apart(1.70 * g, 1.74 * g), ["1.70 GiB".to_string(), "1.74 GiB".to_string()]);
        assert_eq!(super::apart(1.2 * g, 1.7 * g), ["1.2 GiB".to_string(), "1.7 GiB".to_string()]);
        assert_eq!(super::apart(g, g), ["1.0 GiB".to_string(), "1.0 GiB".to_string()]);
    }
}
