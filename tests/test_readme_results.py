"""The README's results table is the one the committed reports/results.json gives (the
report's conclusions, `clearbench report --readme`), and rewriting it is exact."""

from __future__ import annotations

import json

import pytest

from clearbench.harness.cli.main import main
from clearbench.harness.report.readme_table import (
    BEGIN,
    END,
    RESULTS,
    readme_block,
    readme_table,
    update_readme,
)

from .harness_helpers import ROOT


def test_the_readme_table_is_generated_from_the_committed_results():
    results = json.loads((ROOT / RESULTS).read_text(encoding="utf-8"))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme_block(readme) == readme_table(results)
    # one line per engine and preset, the reference first
    assert results["rows"] and results["rows"][0][0].startswith("reference[")


def test_rewriting_the_readme_keeps_the_rest(tmp_path):
    readme = tmp_path / "README.md"
    readme.write_text(f"# title\n\nbefore\n\n{BEGIN}\nold\n{END}\n\nafter\n", encoding="utf-8")
    results = {"head": ["engine", "a | b"], "rows": [["x", "1"]], "standing": "s.",
               "provenance": "3 runs"}
    assert update_readme(readme, results)
    text = readme.read_text(encoding="utf-8")
    assert text.startswith("# title\n\nbefore\n\n") and text.endswith("\n\nafter\n")
    assert "| engine | a \\| b |" in text and "| x | 1 |" in text and "\ns.\n" in text
    assert not update_readme(readme, results)           # unchanged the second time
    readme.write_text("no markers\n", encoding="utf-8")
    with pytest.raises(ValueError, match="no generated results table"):
        update_readme(readme, results)


def test_report_readme_from_results(tmp_path, capsys):
    readme = tmp_path / "README.md"
    readme.write_text(f"{BEGIN}\n{END}\n", encoding="utf-8")
    source = tmp_path / "results.json"
    source.write_text(json.dumps({"head": ["engine"], "rows": [["reference[default]"]],
                                  "standing": "", "provenance": "1 run"}), encoding="utf-8")
    assert main(["report", "--readme", str(readme), "--from-results", str(source)]) == 0
    assert "| reference[default] |" in readme.read_text(encoding="utf-8")
    assert main(["report", "--from-results", str(source)]) == 2
    assert "give --readme too" in capsys.readouterr().err
