//! Real clients read what drapelab writes: the Python `mcap` reader decodes every message of
//! `timeline.mcap`, `rerun-sdk` loads `drape.rrd`, and pyarrow reads `particles.parquet` with the
//! documented columns and types. A failure here means a user's viewer or dataframe cannot open a run.

use crate::support::{root, run_python};

fn simulate_recorded(extra: &[&str]) -> tempfile::TempDir {
    let (tmp, o) = simulate_hang4_recorded(extra);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    tmp
}

/// `drapelab simulate` of hang4 into `o/` of a temporary folder with `timeline.mcap` and `drape.rrd`
/// and the `extra` arguments; the folder and the command's output.
pub(crate) fn simulate_hang4_recorded(extra: &[&str]) -> (tempfile::TempDir, std::process::Output) {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("o");
    let o =
        crate::support::simulate_recorded(&root().join("datasets/scenes/hang4.toml"), &out, extra);
    (tmp, o)
}

#[test]
fn python_mcap_reader_decodes_every_message_of_a_static_and_a_dynamic_timeline() {
    for extra in [
        vec![],
        vec![
            "--set",
            "solver.kind=implicit-euler",
            "--set",
            "solver.dynamic.dt_s=0.01",
            "--set",
            "record.every=5",
        ],
    ] {
        let tmp = simulate_recorded(&extra);
        let path = tmp.path().join("o/timeline.mcap");
        let out = run_python(
            r#"
import sys, json
from mcap.reader import make_reader
n_cloth = n_stats = 0
with open(sys.argv[1], "rb") as f:
    r = make_reader(f)
    for schema, channel, message in r.iter_messages():
        body = json.loads(message.data)
        if channel.topic == "/drapelab/cloth":
            assert schema.name == "foxglove.SceneUpdate" and schema.encoding == "jsonschema"
            tri = body["entities"][0]["triangles"][0]
            assert len(tri["points"]) == 121 and len(tri["indices"]) == 3 * 200
            n_cloth += 1
        else:
            assert channel.topic == "/drapelab/stats" and "max_residual_N" in body
            n_stats += 1
print(n_cloth, n_stats)
"#,
            &[&path],
        );
        let counts: Vec<usize> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
        assert!(counts[0] >= 2 && counts[0] == counts[1], "{out}");
    }
}

#[test]
fn rerun_sdk_loads_the_recording() {
    let tmp = simulate_recorded(&[]);
    let path = tmp.path().join("o/drape.rrd");
    let out = run_python(
        r#"
import sys
from rerun.experimental import RrdReader
reader = RrdReader(sys.argv[1])
assert len(reader.recordings()) == 1
mesh_rows = 0
static_mesh = 0
paths = set()
for chunk in reader.stream().to_chunks():
    paths.add(chunk.entity_path)
    if chunk.entity_path == "/cloth/mesh":
        # The triangles once, without a timeline; the positions per iteration.
        if "iteration" in chunk.timeline_names:
            mesh_rows += chunk.num_rows
        else:
            static_mesh += chunk.num_rows
assert static_mesh >= 1, "no static mesh topology"
assert {"/cloth/mesh", "/cloth/pins", "/stats/max_residual_N", "/stats/energy_J"} <= paths, paths
print(mesh_rows)
"#,
        &[&path],
    );
    assert!(out.trim().parse::<usize>().unwrap() >= 2);
}

#[test]
fn pyarrow_reads_particles_with_documented_columns() {
    let tmp = simulate_recorded(&[]);
    let path = tmp.path().join("o/particles.parquet");
    run_python(
        r#"
import sys, pyarrow.parquet as pq, pyarrow as pa
t = pq.read_table(sys.argv[1])
assert t.schema.names == ["i", "j", "x_m", "y_m", "z_m", "present"], t.schema
assert t.schema.field("present").type == pa.bool_() and all(t.column("present").to_pylist())
assert t.schema.field("i").type == pa.uint32() and t.schema.field("z_m").type == pa.float64()
assert t.num_rows == 121
assert pq.read_metadata(sys.argv[1]).metadata[b"status"] == b"converged"
"#,
        &[&path],
    );
}
