"""Copies a subset of ../shared/cusick/ (samples 1-4 of every fabric: all of fabrics 11-15, which have two) into datasets/cusick/, keeping
the source's layout, file names and column names. Run once, by hand, from the repository root:
    .venv/bin/python datasets/cusick/make.py /work/shared/cusick
drapelab never reads the source folder at run or test time."""
import csv, shutil, sys
from pathlib import Path

import pyarrow.parquet as pq
import pyarrow.compute as pc

SRC = Path(sys.argv[1])
DST = Path(__file__).resolve().parent
MAX_SAMPLE = 4


def keep_csv(name, key="sample"):
    lines = (SRC / name).read_text().splitlines(keepends=True)
    head = [l for l in lines if l.startswith("#")]
    rows = list(csv.DictReader([l for l in lines if not l.startswith("#")]))
    with open(DST / name, "w", newline="") as f:
        f.writelines(head)
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        for r in rows:
            if key is None or int(r[key]) <= MAX_SAMPLE:
                w.writerow(r)


def keep_parquet(name, group=48):
    t = pq.read_table(SRC / name)
    t = t.filter(pc.less_equal(t["sample"], MAX_SAMPLE))
    pq.write_table(t, DST / name, compression="zstd", use_dictionary=False, row_group_size=2699 * group)


for name in ["template_faces.parquet", "template_rest.parquet", "silhouette_scale.md", "fabrics.csv"]:
    shutil.copy(SRC / name, DST / name)
keep_csv("captures_index.csv")
keep_csv("summary_computed.csv")
keep_parquet("captures.parquet")
keep_parquet("hem_curves.parquet", group=1_000_000)
for d in sorted(SRC.glob("fabric_*")):
    out = DST / d.name / "silhouettes"
    out.mkdir(parents=True, exist_ok=True)
    for jpg in sorted((d / "silhouettes").glob("sample_*_capture_*.jpg")):
        if int(jpg.name.split("_")[1]) <= MAX_SAMPLE:
            shutil.copy(jpg, out / jpg.name)
readme = (SRC / "README.md").read_text()
(DST / "README.md").write_text(
    "> **Provenance (drapelab):** a subset (samples 1-4 of fabrics 1-10, both specimens of fabrics 11-15) of `../shared/cusick/`, copied by "
    "`datasets/cusick/make.py` with the source's layout, file names and columns; `fabrics.csv` still gives the "
    "source's counts (12 specimens, 48 captures). The data are the Cusick drape dataset of Gong, Mao & Wang, "
    "\"Bayesian Differentiable Physics for Cloth Digitalization\", CVPR 2024 (arXiv 2402.17664), as described below.\n\n"
    + readme
)
