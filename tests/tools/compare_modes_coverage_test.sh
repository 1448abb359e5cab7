#!/usr/bin/env bash
# scripts/compare_modes.py marks a CC figure the ground station made over less than 95 % of a
# UAV's frames (its accepted batches over the agent's steps), in the table and on stderr, and
# leaves a figure over the whole flight unmarked. Needs only the standard library.
set -uo pipefail
SRC="$1" OUT="$2"
rm -rf "$OUT" && mkdir -p "$OUT" || exit 1
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
"$PY" - "$SRC" "$OUT" <<'PYEOF'
import importlib.util, sys
src, out = sys.argv[1:3]
spec = importlib.util.spec_from_file_location("compare_modes", src + "/scripts/compare_modes.py")
cm = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cm)
summary = {"agents": {"1": {"ate_rmse_m": 0.05, "steps": 1900, "nees_mean": 9.0},
                      "4": {"ate_rmse_m": 0.06, "steps": 1900, "nees_mean": 9.0}}}
gs = {"agents": {"1": {"batches": 1900, "rejected": 0}, "4": {"batches": 7, "rejected": 1893}}}
rows = cm.rows_of("team", 1, "features", "cc", {"summary": summary, "gs": gs, "dir": out})
by_uav = {r["uav"]: r for r in rows}
assert abs(by_uav[1]["coverage"] - 1.0) < 1e-12, by_uav[1]
assert abs(by_uav[4]["coverage"] - 7 / 1900) < 1e-12, by_uav[4]
assert not cm.short_coverage(by_uav[1]) and cm.short_coverage(by_uav[4])
single = cm.rows_of("team", 1, "features", "single", {"summary": summary, "gs": {}, "dir": out})
assert not any(cm.short_coverage(r) for r in single)
cm.write_markdown(out + "/results.md", rows + single, "test")
md = open(out + "/results.md").read()
assert "0.060 † (0 %)" in md, md
assert "0.050 †" not in md, md
assert "less than 95 %" in md, md
print("compare_modes coverage flag: ok")
PYEOF
