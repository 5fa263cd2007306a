"""The worked examples of docs/python.md run as they stand and print what the text says."""

import contextlib
import io
import os
import re

from support import SOURCE


def examples() -> dict[str, str]:
    """The python blocks under "## Worked examples", by their ### title."""
    text = (SOURCE / "docs" / "python.md").read_text()
    section = text.split("## Worked examples", 1)[1].split("\n## ", 1)[0]
    blocks = {}
    for part in section.split("\n### ")[1:]:
        title, rest = part.split("\n", 1)
        blocks[title.strip()] = re.search(r"```python\n(.*?)```", rest, re.S).group(1)
    return blocks


def run_example(title: str, tmp_path) -> str:
    code = examples()[title]
    (tmp_path / "examples").symlink_to(SOURCE / "examples")
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with contextlib.redirect_stdout(out):
            exec(compile(code, f"docs/python.md: {title}", "exec"), {"__name__": "__main__"})
    finally:
        os.chdir(cwd)
        import matplotlib.pyplot as plt

        plt.close("all")
    return out.getvalue()


def pngs(tmp_path) -> dict[str, int]:
    return {p.name: p.stat().st_size for p in tmp_path.glob("*.png")}


def test_the_three_worked_examples_are_there():
    assert list(examples()) == ["The paper's Fig. 2c", "Three buildings under El Centro",
                                "A design task: the joint, then a gap element"]


def test_fig2c(tmp_path):
    out = run_example("The paper's Fig. 2c", tmp_path)
    assert out.splitlines() == ["[0.983, 0.426] [2.0, 2.0]"]
    assert set(pngs(tmp_path)) == {"fig2c.png", "fig2c_gap_loop.png"} and min(pngs(tmp_path).values()) > 10_000


def test_three_buildings_under_el_centro(tmp_path):
    out = run_example("Three buildings under El Centro", tmp_path)
    assert out.splitlines() == ["8-storey frame 8 1.23", "360 impacts"]
    assert len(pngs(tmp_path)) == 4 and min(pngs(tmp_path).values()) > 10_000


def test_the_design_task(tmp_path):
    out = run_example("A design task: the joint, then a gap element", tmp_path).splitlines()
    assert out[0] == "no pounding above 0.212 m; SRSS 0.177 m, ABS 0.251 m, DDC 0.176 m"
    assert out[1] == "bare pounding [0.0111  0.00796] 216 impacts"
    assert out[2] == "best element k, c = (100000000.0, 1000000.0) [0.01062 0.00687] 7 impacts"
    assert min(pngs(tmp_path).values()) > 10_000


def test_the_readmes_sample_output_is_what_the_run_prints(tmp_path):
    """README.md's worked example prints what its text shows (the run time and the folder aside)
    and events.csv starts with the rows it shows: the figures come from a run."""
    import subprocess

    from support import CLI

    readme = (SOURCE / "README.md").read_text()
    command, shown = re.search(r"`(\./build/release/poundsim run examples/fig2c_ratio0\.8\.toml --out (\S+))` prints\n\n```\n(.*?)```",
                               readme, re.S).group(1, 3)
    out = tmp_path / "out"
    printed = subprocess.run([CLI, "run", str(SOURCE / "examples" / "fig2c_ratio0.8.toml"), "--out", str(out)],
                             check=True, capture_output=True, text=True).stdout
    normalise = lambda text: re.sub(r", [0-9.]+ s\)$", ", T s)", text, flags=re.M)
    printed = normalise(printed).replace(str(SOURCE / "examples") + "/", "examples/").replace(str(out), "DIR")
    shown = normalise(shown).replace(command.split("--out ")[1], "DIR")
    assert printed == shown
    rows = re.search(r"`results/fig2c_ratio0\.8/events\.csv` starts\n\n```\n(.*?)```", readme, re.S).group(1)
    written = (out / "events.csv").read_text().splitlines()
    assert rows.splitlines() == written[: len(rows.splitlines())]
