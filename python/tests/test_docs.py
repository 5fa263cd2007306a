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
    """README.md's short example and docs/guide.md's first time history print what their text
    shows (the run time and the folder aside), and events.csv starts with the rows the guide
    shows: the figures come from a run."""
    import subprocess

    from support import CLI

    out = tmp_path / "out"
    printed = subprocess.run([CLI, "run", str(SOURCE / "examples" / "fig2c_ratio0.8.toml"), "--out", str(out)],
                             check=True, capture_output=True, text=True).stdout
    normalise = lambda text: re.sub(r", [0-9.]+ s\)$", ", T s)", text, flags=re.M)
    printed = normalise(printed).replace(str(SOURCE / "examples") + "/", "examples/").replace(str(out), "DIR")
    for page in ("README.md", "docs/guide.md"):
        text = (SOURCE / page).read_text()
        command, shown = re.search(r"`(\./build/release/poundsim run examples/fig2c_ratio0\.8\.toml --out (\S+))` prints\n\n```\n(.*?)```",
                                   text, re.S).group(1, 3)
        shown = normalise(shown).replace(command.split("--out ")[1], "DIR")
        assert printed == shown, page
    guide = (SOURCE / "docs" / "guide.md").read_text()
    rows = re.search(r"`results/fig2c_ratio0\.8/events\.csv` starts\n\n```\n(.*?)```", guide, re.S).group(1)
    written = (out / "events.csv").read_text().splitlines()
    assert rows.splitlines() == written[: len(rows.splitlines())]


def shell_blocks(page: str) -> list[str]:
    """The ```sh blocks of a page, but for the set-up commands (which CI runs as such)."""
    text = (SOURCE / page).read_text()
    return [b for b in re.findall(r"```sh\n(.*?)```", text, re.S) if "install-deps.sh" not in b]


def test_every_command_of_the_readme_and_the_guide_runs(tmp_path):
    """Each shell block of README.md and docs/guide.md runs as written (the program from the
    build tree, in a scratch folder beside the examples) and exits 0; the check prints what the
    guide says."""
    import subprocess

    from support import CLI

    for name in ("examples", "data"):
        (tmp_path / name).symlink_to(SOURCE / name)
    (tmp_path / "python").symlink_to(SOURCE / "python")
    blocks = shell_blocks("README.md") + shell_blocks("docs/guide.md")
    assert len(blocks) >= 5
    outputs = []
    for block in blocks:
        script = "set -euo pipefail\n" + block.replace("./build/release/poundsim", CLI)
        done = subprocess.run(["bash", "-c", script], cwd=tmp_path, capture_output=True, text=True,
                              env={**os.environ, "MPLBACKEND": "Agg"})
        assert done.returncode == 0, f"{block}\n{done.stderr}"
        outputs.append(done.stdout)
    guide = (SOURCE / "docs" / "guide.md").read_text()
    said = re.search(r"prints `(examples/study_eta_mu\.toml: valid: [^`]*)`", guide, re.S).group(1)
    assert " ".join(said.split()) + "\n" in outputs
    assert (tmp_path / "results" / "laws" / "comparison.png").stat().st_size > 10_000


def test_the_guides_python_lines_run(tmp_path):
    """docs/guide.md's Python in a few lines runs as it stands."""
    text = (SOURCE / "docs" / "guide.md").read_text()
    section = text.split("## Python in a few lines", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    (tmp_path / "examples").symlink_to(SOURCE / "examples")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        namespace = {"__name__": "__main__"}
        exec(compile(code, "docs/guide.md: Python in a few lines", "exec"), namespace)
    finally:
        os.chdir(cwd)
        import matplotlib.pyplot as plt

        plt.close("all")
    assert (tmp_path / "envelopes.png").stat().st_size > 10_000
    assert namespace["th"].time[-1] > 0
