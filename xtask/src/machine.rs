//! What the benchmarks ran on: CPU model, cores, memory, compiler, date and load.

use std::time::{SystemTime, UNIX_EPOCH};

/// The machine and toolchain the tables were measured with.
#[derive(Debug, Clone)]
pub struct Machine {
    /// CPU model name from `/proc/cpuinfo` (or "unknown CPU"), with its family, model and
    /// widest vector extension where it says (cloud machines of one name differ in them,
    /// and the kernels run twice as fast with AVX-512 as with AVX2).
    pub cpu: String,
    /// Hardware threads the process may use (`std::thread::available_parallelism`).
    pub cores: usize,
    /// Total memory in GiB, when `/proc/meminfo` says.
    pub memory_gib: Option<f64>,
    /// `rustc --version` of the compiler that built the xtask.
    pub rustc: String,
    /// Operating system and kernel release.
    pub os: String,
    /// Start of the run, "YYYY-MM-DD HH:MM UTC".
    pub date: String,
}

impl Machine {
    /// Reads the machine description.
    pub fn detect() -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu = cpuinfo
            .lines()
            .find(|l| l.starts_with("model name"))
            .and_then(|l| l.split_once(':'))
            .map_or_else(
                || "unknown CPU".to_owned(),
                |(_, v)| v.split_whitespace().collect::<Vec<_>>().join(" "),
            );
        let cpu = format!("{cpu}{}", cpu_details(&cpuinfo));
        let memory_gib = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|m| {
                m.lines()
                    .find(|l| l.starts_with("MemTotal:"))
                    .and_then(|l| l.split_whitespace().nth(1))
                    .and_then(|kb| kb.parse::<f64>().ok())
            })
            .map(|kb| kb / (1024.0 * 1024.0));
        let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
        let os = format!("{} {}", std::env::consts::OS, kernel.trim())
            .trim()
            .to_owned();
        Self {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            memory_gib,
            rustc: env!("XTASK_RUSTC_VERSION").to_owned(),
            os,
            date: utc_now(),
        }
    }

    /// One line: "CPU, N cores, M GiB, os, rustc".
    pub fn summary(&self) -> String {
        let memory = self
            .memory_gib
            .map(|g| format!(", {g:.0} GiB RAM"))
            .unwrap_or_default();
        format!(
            "{}, {} core{}{memory}, {}, {}",
            self.cpu,
            self.cores,
            if self.cores == 1 { "" } else { "s" },
            self.os,
            self.rustc
        )
    }
}

/// " (family F model M, AVX-512)" from `/proc/cpuinfo`'s first processor; empty where it
/// says none of it.
fn cpu_details(cpuinfo: &str) -> String {
    let field = |name: &str| {
        cpuinfo
            .lines()
            .find(|l| l.split(':').next().map(str::trim) == Some(name))
            .and_then(|l| l.split_once(':'))
            .map(|(_, v)| v.trim().to_owned())
    };
    let mut parts = Vec::new();
    if let (Some(family), Some(model)) = (field("cpu family"), field("model")) {
        parts.push(format!("family {family} model {model}"));
    }
    if let Some(flags) = field("flags") {
        let has = |f: &str| flags.split_whitespace().any(|x| x == f);
        if has("avx512f") {
            parts.push("AVX-512".to_owned());
        } else if has("avx2") {
            parts.push("AVX2".to_owned());
        }
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!(" ({})", parts.join(", "))
    }
}

/// The 1-minute load average from `/proc/loadavg`.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// CPU time counters at one moment: all CPUs' busy and total time (`/proc/stat`) and
/// this process's own CPU time (`/proc/self/stat`), in clock ticks.
#[derive(Debug, Clone, Copy)]
pub struct CpuSample {
    busy: u64,
    total: u64,
    own: u64,
    cpus: usize,
}

impl CpuSample {
    /// Reads the counters; `None` where `/proc` is not available.
    pub fn now() -> Option<Self> {
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        let mut lines = stat.lines();
        let fields: Vec<u64> = lines
            .next()?
            .split_whitespace()
            .skip(1)
            .filter_map(|v| v.parse().ok())
            .collect();
        // user nice system idle iowait irq softirq steal (guest time is inside user).
        let get = |k: usize| fields.get(k).copied().unwrap_or(0);
        let busy = get(0) + get(1) + get(2) + get(5) + get(6) + get(7);
        let total = busy + get(3) + get(4);
        let cpus = lines.filter(|l| l.starts_with("cpu")).count().max(1);
        let own_stat = std::fs::read_to_string("/proc/self/stat").ok()?;
        let after_name = own_stat.rsplit_once(')')?.1;
        // Fields after the name start at field 3 (state); utime and stime are fields 14
        // and 15 of proc(5).
        let tokens: Vec<&str> = after_name.split_whitespace().collect();
        let field =
            |k: usize| -> u64 { tokens.get(k - 3).and_then(|v| v.parse().ok()).unwrap_or(0) };
        let own = field(14) + field(15);
        Some(Self {
            busy,
            total,
            own,
            cpus,
        })
    }

    /// Cores kept busy on average by *other* processes between `self` and `later`.
    pub fn others_cores(&self, later: &Self) -> Option<f64> {
        let total = later.total.checked_sub(self.total)?;
        if total == 0 {
            return None;
        }
        let busy = later.busy.saturating_sub(self.busy);
        let own = later.own.saturating_sub(self.own);
        Some(busy.saturating_sub(own) as f64 / total as f64 * self.cpus as f64)
    }
}

/// Now as "YYYY-MM-DD HH:MM UTC".
fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let (y, m, d) = civil_date(days);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        (rem % 3600) / 60
    )
}

/// Gregorian (year, month, day) of a day count since 1970-01-01, by 400-year eras.
fn civil_date(days: i64) -> (i64, u32, u32) {
    // Shift the epoch to 0000-03-01 so that leap days fall at the end of a year.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z.rem_euclid(146_097);
    let year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let month_index = (5 * day_of_year + 2) / 153; // 0 = March
    let day = (day_of_year - (153 * month_index + 2) / 5 + 1) as u32;
    let month = if month_index < 10 {
        month_index + 3
    } else {
        month_index - 9
    } as u32;
    let year = year_of_era + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

#[cfg(test)]
mod tests {
    use super::civil_date;

    #[test]
    fn known_dates() {
        assert_eq!(civil_date(0), (1970, 1, 1));
        assert_eq!(civil_date(59), (1970, 3, 1));
        assert_eq!(civil_date(11_016), (2000, 2, 29));
        assert_eq!(civil_date(19_782), (2024, 2, 29));
        assert_eq!(civil_date(20_454), (2026, 1, 1));
    }
}
