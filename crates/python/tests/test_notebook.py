"""docs/notebooks/tour.ipynb runs from top to bottom (nbclient, a real Jupyter kernel): every
code cell ran without error, the plot and the pictures are there as PNG outputs, and the
picture it saves is a PNG of the size the renderer draws."""

import base64

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")


def test_the_tour_notebook_runs_and_shows_its_pictures(root, tmp_path):
    nb = nbformat.read(root / "docs" / "notebooks" / "tour.ipynb", as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(root)}}).execute()
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.execution_count for c in code), "every code cell ran"
    errors = [o for c in code for o in c.outputs if o.output_type == "error"]
    assert not errors, errors
    pngs = [o for c in code for o in c.outputs if "image/png" in o.get("data", {})]
    # The series plot, the simulation's picture and the run's frame.
    assert len(pngs) >= 3, [list(o.get("data", {})) for c in code for o in c.outputs]
    for o in pngs:
        assert base64.b64decode(o["data"]["image/png"])[:8] == b"\x89PNG\r\n\x1a\n"
    saved = (root / "out" / "tour.png").read_bytes()
    assert saved[:8] == b"\x89PNG\r\n\x1a\n" and len(saved) > 10_000
    # Kept for the record of the run (CI's log names it).
    nbformat.write(nb, tmp_path / "tour.executed.ipynb")
