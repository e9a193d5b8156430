#!/usr/bin/env bash
# The book (docs/): built with mdBook, its links checked. mdBook is installed by this script on first
# use into .tools/ (cargo install from crates.io, pinned, no default features: about 3 min on 2 cores
# once; CARGO_TARGET_DIR is shared so a warm machine skips it) and reused after. The links of the
# sources are checked by `cargo test` (tests/it/docs.rs: every relative link resolves and none
# leaves docs/src); here the rendered book is checked too: every page of SUMMARY.md is rendered
# and every relative link between the rendered pages finds its page. Run by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
version=0.4.52
tools="$PWD/.tools"
mdbook="$tools/bin/mdbook"
if ! "$mdbook" --version 2>/dev/null | grep -q "$version"; then
    cargo install mdbook --version "$version" --no-default-features --locked --root "$tools" --quiet
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$mdbook" build docs --dest-dir "$out" >/dev/null 2>&1 || "$mdbook" build docs --dest-dir "$out"
python3 - "$out" docs/src/SUMMARY.md <<'PY'
import html.parser, os, re, sys
out, summary = sys.argv[1], sys.argv[2]
pages = re.findall(r"\]\(([^)]+\.md)\)", open(summary).read())
missing = [p for p in pages if not os.path.exists(os.path.join(out, p[:-3] + ".html"))]
class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(); self.links = []
    def handle_starttag(self, tag, attrs):
        for k, v in attrs:
            if k in ("href", "src") and v and not re.match(r"^[a-z]+:|^#|^//", v):
                self.links.append(v.split("#")[0])
broken = []
for p in pages:
    page = os.path.join(out, p[:-3] + ".html")
    if not os.path.exists(page):
        continue
    parser = Links(); parser.feed(open(page, encoding="utf-8").read())
    for l in parser.links:
        if l and not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(page), l))):
            broken.append(f"{p}: {l}")
for m in missing:
    print(f"not rendered: {m}", file=sys.stderr)
for b in broken:
    print(f"broken link: {b}", file=sys.stderr)
if missing or broken:
    sys.exit(1)
print(f"book: {len(pages)} pages rendered, their links resolve")
PY
