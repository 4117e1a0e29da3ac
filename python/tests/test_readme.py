"""The notebook-style example of python/README.md runs as written and prints
what it shows under each cell. (The repository's README points to it rather
than copying it.)"""

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def python_section(path):
    """The Python section of a README: from `## Python` to the next `## `."""
    text = path.read_text()
    start = text.index("## Python")
    end = text.find("\n## ", start + 1)
    return text[start:] if end < 0 else text[start:end]


def test_the_readme_example_prints_what_it_shows(tmp_path, monkeypatch):
    path = README
    cells = re.findall(r"```python\n(.*?)```\n```text\n(.*?)```", python_section(path), flags=re.S)
    assert len(cells) >= 4, "python/README.md: expected ```python cells, each followed by its ```text output"
    monkeypatch.chdir(tmp_path)  # the example writes calibrated.toml here
    namespace = {}
    for code, shown in cells:
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, str(path), "exec"), namespace)
        assert printed.getvalue() == shown, f"the cell\n{code}\nprinted\n{printed.getvalue()}"
    assert (tmp_path / "calibrated.toml").is_file()
    # The example's claim: the calibration lands within its stated uncertainty of the truth.
    result, truth = namespace["result"], namespace["truth"]
    assert abs((result.anchors_m - truth.anchors_m) / result.anchor_sigma_m).max() < 3.0
