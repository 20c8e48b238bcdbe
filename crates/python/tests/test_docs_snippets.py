"""Every Python block that README.md and docs/python.md show runs, in the order a reader meets
them, as a new user would run it (issue 53): each block is taken from the page itself (never
copied here), written to a script of its own and run by a fresh interpreter in a fresh
directory laid out as a clone (the repository's `scenes/`), one after the other in the same
directory, as a reader would. The packages that the page's own install lines do not install
cannot be imported there (README: only NumPy, which the package depends on), so a block that
needs pandas or matplotlib without saying so fails here. Then what the blocks promise is on
disk: the run of README's block, and the four points of the sweep example (which on main ran
nothing and exited 0, without its `if __name__ == "__main__":` guard under `spawn`)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT

# What each page's install lines make importable besides the package and NumPy.
PAGES = [
    ("README.md", []),
    ("docs/python.md", ["pandas", "tqdm", "matplotlib"]),
]
NOT_INSTALLED = ["pandas", "tqdm", "matplotlib", "IPython", "ipykernel", "xarray"]

# Prepended to each block: what the page did not install cannot be imported.
GUARD = """
import sys
class _NotInstalled:
    def __init__(self, names): self.names = names
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in self.names:
            raise ModuleNotFoundError(f"No module named {{name!r}} (the page's install lines do not install it)")
        return None
sys.meta_path.insert(0, _NotInstalled({blocked!r}))
"""


def python_blocks(page: Path):
    return re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)


def test_every_python_snippet_of_the_docs_runs_in_order(tmp_path):
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    ran = 0
    for page, installed in PAGES:
        blocked = [n for n in NOT_INSTALLED if n not in installed]
        blocks = python_blocks(ROOT / page)
        assert blocks, f"{page} shows no Python block"
        for k, block in enumerate(blocks):
            script = tmp_path / f"{Path(page).stem}_{k}.py"
            script.write_text(GUARD.format(blocked=blocked) + block)
            o = subprocess.run(
                [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, env=env, timeout=600
            )
            assert o.returncode == 0, f"{page}, Python block {k + 1}:\n{block}\n{o.stderr[-3000:]}"
            ran += 1
    assert ran >= 2
    # README's block wrote a whole run; the sweep example ran its four points.
    assert (tmp_path / "out" / "python" / "complete").is_file()
    done = sorted(p.parent.name for p in (tmp_path / "out" / "py-sweep" / "runs").glob("*/complete"))
    assert done == [
        "model.zeta=0.005_seed=1",
        "model.zeta=0.005_seed=2",
        "model.zeta=0_seed=1",
        "model.zeta=0_seed=2",
    ], done
