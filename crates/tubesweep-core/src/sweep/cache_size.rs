//! The size of the processor's last-level cache, as Linux reports it in sysfs
//! (`/sys/devices/system/cpu/cpuN/cache/indexM/{level,type,size}`). The sweeps use it to decide
//! when their rows outgrow the cache ([`crate::sweep`]'s row prefetch).

use std::path::Path;
use std::sync::OnceLock;

/// The last-level cache assumed where the system does not say: 32 MiB.
pub const ASSUMED_LAST_LEVEL_CACHE: usize = 32 << 20;

/// The size in bytes of the highest-level data or unified cache that Linux reports for the
/// first CPU that has a readable cache directory (`cpu0` first), read once; 32 MiB
/// ([`ASSUMED_LAST_LEVEL_CACHE`]) where none can be read (other systems, some containers).
pub fn last_level_cache_bytes() -> usize {
    static SIZE: OnceLock<usize> = OnceLock::new();
    *SIZE.get_or_init(|| last_level_cache_in(Path::new("/sys/devices/system/cpu")).unwrap_or(ASSUMED_LAST_LEVEL_CACHE))
}

/// [`last_level_cache_bytes`] read from `cpu_root` (sysfs's `devices/system/cpu` or a copy of
/// its shape): `cpu0/cache` first, then the other `cpuN/cache` in order of N.
pub fn last_level_cache_in(cpu_root: &Path) -> Option<usize> {
    if let Some(size) = cache_dir_last_level(&cpu_root.join("cpu0").join("cache")) {
        return Some(size);
    }
    let mut cpus: Vec<(u32, std::path::PathBuf)> = std::fs::read_dir(cpu_root)
        .ok()?
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            let n = name.strip_prefix("cpu")?.parse::<u32>().ok()?;
            Some((n, e.path()))
        })
        .collect();
    cpus.sort();
    cpus.iter().find_map(|(_, p)| cache_dir_last_level(&p.join("cache")))
}

/// The size of the highest-level data or unified cache with a size above zero among the
/// `index*` entries of one CPU's cache directory.
fn cache_dir_last_level(dir: &Path) -> Option<usize> {
    let mut best: Option<(u32, usize)> = None;
    for entry in std::fs::read_dir(dir).ok()?.flatten() {
        let path = entry.path();
        let read = |f: &str| std::fs::read_to_string(path.join(f)).ok().map(|s| s.trim().to_string());
        if read("type").as_deref() == Some("Instruction") {
            continue;
        }
        let Some(level) = read("level").and_then(|l| l.parse::<u32>().ok()) else {
            continue;
        };
        let Some(size) = read("size").and_then(|s| parse_cache_size(&s)).filter(|&s| s > 0) else {
            continue;
        };
        if best.is_none_or(|(l, _)| level > l) {
            best = Some((level, size));
        }
    }
    best.map(|(_, size)| size)
}

/// Parses sysfs's cache sizes: "32768K", "1M", "512" (bytes).
fn parse_cache_size(s: &str) -> Option<usize> {
    let (digits, unit) = match s.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((i, _)) => s.split_at(i),
        None => (s, ""),
    };
    let n: usize = digits.parse().ok()?;
    let scale = match unit.trim() {
        "" => 1,
        "K" | "k" | "KiB" => 1 << 10,
        "M" | "MiB" => 1 << 20,
        "G" | "GiB" => 1 << 30,
        _ => return None,
    };
    n.checked_mul(scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[test]
    fn cache_sizes_parse_as_sysfs_writes_them() {
        assert_eq!(parse_cache_size("32768K"), Some(32 << 20));
        assert_eq!(parse_cache_size("1M"), Some(1 << 20));
        assert_eq!(parse_cache_size("512"), Some(512));
        assert_eq!(parse_cache_size("12 MiB"), Some(12 << 20));
        assert_eq!(parse_cache_size("lots"), None);
        assert_eq!(parse_cache_size("3X"), None);
        assert_eq!(parse_cache_size(""), None);
        assert!(last_level_cache_bytes() > 0);
    }

    /// Writes `index{i}` entries `(level, type, size)` under `root/cpu{cpu}/cache`, plus the
    /// `uevent` file sysfs has there; a `None` field is left out.
    fn fake_cpu(root: &Path, cpu: u32, entries: &[(Option<&str>, Option<&str>, Option<&str>)]) {
        let dir = root.join(format!("cpu{cpu}")).join("cache");
        fs::create_dir_all(&dir).unwrap();
        fs::write(dir.join("uevent"), "").unwrap();
        for (i, (level, kind, size)) in entries.iter().enumerate() {
            let e = dir.join(format!("index{i}"));
            fs::create_dir_all(&e).unwrap();
            for (name, value) in [("level", level), ("type", kind), ("size", size)] {
                if let Some(v) = value {
                    fs::write(e.join(name), format!("{v}\n")).unwrap();
                }
            }
        }
    }

    #[test]
    fn the_last_level_is_the_highest_data_or_unified_cache_with_a_size() {
        let root = std::env::temp_dir().join(format!("tubesweep-cache-size-{}", std::process::id()));
        let _ = fs::remove_dir_all(&root);
        // an instruction cache at a higher level than any other does not count, a level whose
        // size is missing or zero falls back to the next one down
        fake_cpu(
            &root.join("a"),
            0,
            &[
                (Some("1"), Some("Data"), Some("48K")),
                (Some("1"), Some("Instruction"), Some("32K")),
                (Some("2"), Some("Unified"), Some("1024K")),
                (Some("3"), Some("Unified"), Some("32768K")),
                (Some("4"), Some("Instruction"), Some("99M")),
            ],
        );
        assert_eq!(last_level_cache_in(&root.join("a")), Some(32 << 20));
        fake_cpu(
            &root.join("b"),
            0,
            &[
                (Some("2"), Some("Unified"), Some("2048K")),
                (Some("3"), Some("Unified"), Some("0K")),
                (Some("3"), Some("Unified"), None),
            ],
        );
        assert_eq!(last_level_cache_in(&root.join("b")), Some(2 << 20));
        // no cpu0 (a container's view): the first CPU that has one, in order of its number
        fs::create_dir_all(root.join("c")).unwrap();
        fs::write(root.join("c").join("online"), "2-3\n").unwrap();
        fake_cpu(&root.join("c"), 11, &[(Some("2"), Some("Unified"), Some("4M"))]);
        fake_cpu(&root.join("c"), 3, &[(Some("3"), Some("Unified"), Some("16M"))]);
        assert_eq!(last_level_cache_in(&root.join("c")), Some(16 << 20));
        // nothing readable
        fake_cpu(
            &root.join("d"),
            0,
            &[
                (None, Some("Unified"), Some("4M")),
                (Some("x"), Some("Data"), Some("1M")),
            ],
        );
        assert_eq!(last_level_cache_in(&root.join("d")), None);
        assert_eq!(last_level_cache_in(&root.join("missing")), None);
        fs::remove_dir_all(&root).unwrap();
    }
}
