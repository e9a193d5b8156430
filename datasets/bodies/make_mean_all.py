#!/usr/bin/env python3
"""Writes datasets/bodies/mean_all.obj from GarmentCode's assets/bodies/mean_all.obj.

Provenance: github.com/maria-korosteleva/GarmentCode at d449629 (MIT licence, copied to
datasets/garments/LICENSE_GarmentCode.txt), the mean body of its body model
(github.com/mbotsch/GarmentMeasurements) that the bundled sample patterns are drafted and placed
for. Usage: `python3 make_mean_all.py SOURCE.obj PATH/TO/drapelab` (the binary checks the body).

1. Turned once from y up to drapelab's z up: (x, y, z) -> (x, -z, y) (metres; the body faces -y);
   normals and texture coordinates dropped.
2. The source surface crosses itself at the lips and the crotch. Until drapelab accepts it as a
   body (`simulate` of datasets/garments/sew.toml names the first edge crossing a face), the
   crossing's edge, its face and their two-ring of neighbours are smoothed: three rounds moving
   each vertex half way to the mean of its neighbours (174 vertices over 9 rounds).
Standard library only.
"""
import re
import subprocess
import sys

HERE = __file__.rsplit("/", 1)[0] or "."
OUT = f"{HERE}/mean_all.obj"
SCENE = f"{HERE}/../garments/sew.toml"


def read(src):
    v, f = [], []
    for line in open(src):
        t = line.split()
        if t and t[0] == "v":
            x, y, z = map(float, t[1:4])
            v.append([x, -z, y])
        elif t and t[0] == "f":
            f.append([int(w.split("/")[0]) - 1 for w in t[1:4]])
    return v, f


def write(v, f):
    with open(OUT) as old:
        head = [l for l in old if l.startswith("#")]
    with open(OUT, "w") as out:
        out.writelines(head)
        out.writelines("v %.10f %.10f %.10f\n" % tuple(p) for p in v)
        out.writelines("f %d %d %d\n" % tuple(i + 1 for i in t) for t in f)


def crossing(binary):
    r = subprocess.run([binary, "simulate", SCENE, "--set", "cloth.resolution_m=0.2",
                        "--out", "/tmp/make_mean_all"], capture_output=True, text=True)
    m = re.search(r"edge from vertex (\d+) to (\d+) passes through face (\d+)", r.stderr)
    return m and (int(m[1]) - 1, int(m[2]) - 1, int(m[3]) - 1)


def main(src, binary):
    v, f = read(src)
    nbr = [set() for _ in v]
    for a, b, c in f:
        nbr[a] |= {b, c}
        nbr[b] |= {a, c}
        nbr[c] |= {a, b}
    write(v, f)
    while (hit := crossing(binary)):
        a, b, face = hit
        region = {a, b, *f[face]}
        region |= set().union(*(nbr[p] for p in region))
        for _ in range(3):
            new = {p: [0.5 * v[p][k] + 0.5 * sum(v[q][k] for q in nbr[p]) / len(nbr[p])
                       for k in range(3)] for p in region}
            for p, q in new.items():
                v[p] = q
        write(v, f)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
