//! The memory a solve needs, estimated before it starts: a sheet too large for the machine is
//! refused up front with the estimate, never run until the kernel kills it.

/// The peak resident memory of a solve per particle, bytes: the sparse factor of the Hessian
/// (nested dissection's fill grows a little faster than the particles), the Hessian's blocks,
/// self-contact's candidate sets and the recorders. Measured resident peaks (`/usr/bin/time -v`,
/// docs/src/science/limits.md): 16 kB a particle on hang4 at 161² (25,921 particles), 22 kB on
/// the dress form's skirt refined to about 85,000 particles with self-contact; rounded up.
pub const BYTES_PER_PARTICLE: f64 = 25e3;

/// The machine's memory, bytes (`MemTotal` of /proc/meminfo); None where it cannot be read.
pub fn machine_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0)
}

/// Why a sheet of `particles` particles cannot be solved on this machine, or None when its
/// estimated peak ([`BYTES_PER_PARTICLE`]) fits in the machine's memory.
pub fn too_large(particles: f64) -> Option<String> {
    let machine = machine_bytes()?;
    let need = particles * BYTES_PER_PARTICLE;
    (need > machine).then(|| {
        format!(
            "{particles:.0} particles need about {:.1} GB (an estimated {:.0} kB each) and this \
machine has {:.1} GB: use a coarser sheet",
            need / 1e9,
            BYTES_PER_PARTICLE / 1e3,
            machine / 1e9
        )
    })
}
