"""tools/physics_rows.py --compare: figures that differ, and scenes and figures one table lacks."""

from __future__ import annotations

from tools.physics_rows import compare


def _table(path, rows):
    path.write_text("".join("\t".join(map(str, row)) + "\n" for row in rows) + "# done\n")
    return str(path)


def test_compare_names_each_difference_and_what_one_table_lacks(tmp_path, capsys):
    base = _table(tmp_path / "base.tsv", [
        ("ball", 0.001, "apex", "error", 1e-6, True, 0.1),
        ("ball", 0.001, "apex", "rest_time", 0.45, True, 0.1),
        ("gone", 0.001, "stop", "error", 2.0, True, 0.1),
    ])
    this = _table(tmp_path / "this.tsv", [
        ("ball", 0.001, "apex", "error", 2e-6, True, 0.2),   # larger
        ("ball", 0.001, "apex", "rest_time", 0.45, True, 0.2),  # same value: not listed
        ("ball", 0.001, "apex", "new_figure", 1.0, True, 0.2),
        ("new", 0.001, "stop", "error", 2.0, False, 0.1),
    ])
    assert compare(base, this) == 1
    out = capsys.readouterr().out
    assert "ball apex error: base 1e-06 (True), this 2e-06 (True), relative difference " \
           "5.00e-01, larger magnitude: this" in out
    assert "rest_time" not in out
    assert "scenes in base only: gone" in out and "scenes in this only: new" in out
    assert "figures in this only: ball apex new_figure" in out
    assert "2 figures of 1 scenes in both tables; 1 differ" in out
