"""The example of python/README.md runs as written."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_example_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "python/README.md has no ```python blocks"
    monkeypatch.chdir(tmp_path)  # the example writes its files here
    namespace = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)
    # The example's own claim: the calibration lands within its stated uncertainty of the truth.
    result, truth = namespace["result"], namespace["truth"]
    assert abs((result.anchors_m - truth.anchors_m) / result.anchor_sigma_m).max() < 4.5
