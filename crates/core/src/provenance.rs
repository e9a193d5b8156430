//! Where and when a result was made, for the records that carry it (run.json, the run lock): the
//! host, a UTC time stamp and the build of drapelab that ran.

use std::time::{Duration, SystemTime, UNIX_EPOCH};

/// This machine's host name: the kernel's (`/proc/sys/kernel/hostname`), else `$HOSTNAME`, else
/// "unknown host".
pub fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok().filter(|s| !s.is_empty()))
        .unwrap_or_else(|| "unknown host".into())
}

/// A Unix time (s) as an RFC 3339 UTC time stamp, e.g. `2026-11-27T01:12:03Z`.
pub fn utc(unix_s: u64) -> String {
    humantime::format_rfc3339_seconds(UNIX_EPOCH + Duration::from_secs(unix_s)).to_string()
}

/// Now, as Unix time in s.
pub fn unix_now_s() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// How long ago `unix_s` was, in words ("40 s", "12 min", "3 h", "2 days").
pub fn age(unix_s: u64) -> String {
    let s = unix_now_s().saturating_sub(unix_s);
    match s {
        0..120 => format!("{s} s"),
        120..7200 => format!("{} min", s / 60),
        7200..172_800 => format!("{} h", s / 3600),
        _ => format!("{} days", s / 86_400),
    }
}

/// The first 16 hex digits of the blake3 hash of the running executable: a rebuilt drapelab
/// (changed code) has another, rebuilding unchanged code gives the same. Hashed once per process.
pub fn build_id() -> &'static str {
    static ID: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    ID.get_or_init(|| {
        let hash = |p: std::path::PathBuf| -> std::io::Result<String> {
            let mut h = blake3::Hasher::new();
            std::io::copy(&mut std::fs::File::open(p)?, &mut h)?;
            Ok(h.finalize().to_hex()[..16].to_string())
        };
        std::env::current_exe()
            .and_then(hash)
            .unwrap_or_else(|_| "unknown".into())
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_time_stamp_is_utc_and_an_age_is_in_words() {
        assert_eq!(super::utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(super::utc(1_795_713_913), "2026-11-26T17:25:13Z");
        let now = super::unix_now_s();
        assert_eq!(super::age(now - 30), "30 s");
        assert_eq!(super::age(now - 600), "10 min");
        assert_eq!(super::build_id().len(), 16);
    }
}
