"""The README runs as printed and every number it shows is checked.

* Every ``python`` block runs (in a scratch folder). A block that uses names it does not define
  runs after the earlier blocks of its section that define them, as a reader would. An expression
  statement whose trailing comment starts with a value (``result.fallbacks  # 0: ...``,
  ``print(score)  # 290.4 (...)``) is a claim: the value (or what it prints) must read as the
  comment's start, numbers to the decimals the comment shows.
* Every ``fcplan`` command of a shell block runs, or is listed in :data:`NOT_RUN` with the
  reason; the output block after ``fcplan run ...`` must be what the command prints (wall and
  solve times aside).
* The numbers of the prose are checked one by one below, and the Benchmarks section's figures
  must be figures recorded in ``bench/README.md``.

Blocks that take more than a few seconds are marked ``slow`` (:data:`SLOW`).
"""

from __future__ import annotations

import ast
import builtins
import contextlib
import io
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from fcplan import scheduling

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"

#: Python blocks (identified by a line they contain) that take more than a few seconds.
SLOW = {
    'demonstrations("milp"': "milp demonstrations, behaviour cloning and evaluation",
    'run_episode(24, "milp"': "a milp episode with a recording",
}

#: ``fcplan`` commands of the README that the test does not run, and why.
NOT_RUN = {
    "fcplan replay run.npz": "opens a window (needs a display); the video commands run",
    "fcplan play": "the interactive game (a window)",
    "fcplan play --scenario 12 --seed 3": "the interactive game (a window)",
    "fcplan sweep study.toml": "the 1,500-episode study (hours)",
    "fcplan sweep study.toml --dask local": "the 1,500-episode study (hours)",
    "fcplan compare --scenarios 1-3 --schedulers greedy,cbba,random --seeds 0-1": (
        "run, output checked, by tests/cli/test_compare_readme.py"
    ),
    "fcplan compare --scenarios 1-3 --schedulers greedy,random --seeds auto": (
        "run, output checked, by tests/cli/test_compare_readme.py"
    ),
    "fcplan report results/study --html": "needs the study's results",
    "fcplan sweep bench/suite_v1_hard.toml --results bench/results/bench-v1 --jobs 2": (
        "the leaderboard's hard-tier study (960 episodes, hours of CPU)"
    ),
    "fcplan sweep bench/suite_v1_scale.toml --results bench/results/bench-v1 --jobs 2": (
        "the leaderboard's scale-tier study (hours of CPU)"
    ),
    "fcplan sweep bench/suite_v2_hard.toml --results bench/results/bench-v2 --jobs 2": (
        "the leaderboard's v2 hard-tier study (1,080 episodes, hours of CPU)"
    ),
    "fcplan leaderboard bench/results/bench-v2 -o docs/leaderboard.md": (
        "rewrites docs/leaderboard.md from the committed results (a minute); tests/experiments "
        "test the leaderboard on small ones"
    ),
}

#: Commands that run but take more than a few seconds.
SLOW_COMMANDS = {
    "fcplan replay run.npz --video run.mp4",
    "SDL_VIDEODRIVER=dummy fcplan play",
}

_NUMBER = r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
_CLAIM_START = re.compile(r"""^(?:-?\d|[(\[{'"]|True\b|False\b|None\b)""")


@dataclass(frozen=True)
class Block:
    """A fenced code block of the README."""

    lang: str
    code: str
    line: int  # line of the opening fence
    section: str  # the heading above it

    @property
    def id(self) -> str:
        return f"L{self.line}"


def blocks() -> list[Block]:
    """Every fenced block of the README, in order."""
    out, section, fence = [], "", None
    lines = README.read_text(encoding="utf-8").splitlines()
    for i, line in enumerate(lines, 1):
        if fence is None and line.startswith("#"):
            section = line.lstrip("#").strip()
        elif fence is None and line.startswith("```"):
            fence, lang, body = i, line[3:].strip(), []
        elif fence is not None and line.startswith("```"):
            out.append(Block(lang, "\n".join(body) + "\n", fence, section))
            fence = None
        elif fence is not None:
            body.append(line)
    return out


PYTHON = [b for b in blocks() if b.lang == "python"]


def _defined(tree: ast.AST) -> set[str]:
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.ExceptHandler) and node.name:
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


def _free(tree: ast.AST) -> set[str]:
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
    return used - _defined(tree) - set(dir(builtins))


def prerequisites(block: Block) -> list[Block]:
    """The earlier blocks of ``block``'s section it needs for its free names, in order."""
    missing = _free(ast.parse(block.code))
    before = [b for b in PYTHON if b.section == block.section and b.line < block.line]
    needed = []
    for b in reversed(before):
        if not missing:
            break
        tree = ast.parse(b.code)
        if missing & _defined(tree):
            needed.insert(0, b)
            missing = (missing - _defined(tree)) | _free(tree)
    assert not missing, f"README block at line {block.line} uses undefined {sorted(missing)}"
    return needed


def _plain(value: Any) -> Any:
    """``value`` with numpy scalars as Python numbers (their repr is what a reader sees)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (tuple, list)):
        return type(value)(_plain(v) for v in value)
    return value


def claim_holds(actual: str, comment: str) -> bool:
    """Whether ``comment`` starts with ``actual``, numbers compared to the comment's decimals.

    Examples
    --------
    >>> claim_holds("(54, [])", "(54, []): 27 scenarios x 2 ticks")
    True
    >>> claim_holds("290.4123 -169.66", "290.4 -169.7 (random)"), claim_holds("82", "81")
    (True, False)
    """
    parts = re.split(f"({_NUMBER})", " ".join(actual.split()))
    pattern = "".join(
        f"({_NUMBER})" if k % 2 else r"\s*" + r"\s*".join(map(re.escape, p.split())) + r"\s*"
        for k, p in enumerate(parts)
    )
    m = re.match(pattern, " ".join(comment.split()))
    if m is None:
        return False
    for got, shown in zip(parts[1::2], m.groups(), strict=True):
        decimals = len(shown.split(".")[1]) if "." in shown and "e" not in shown.lower() else 0
        if abs(float(got) - float(shown)) > 0.5 * 10.0**-decimals + 1e-12:
            return False
    return True


def _comment_of(source: str, node: ast.stmt) -> str | None:
    """The trailing comment of ``node``'s last line, if it starts with a value."""
    rest = source.splitlines()[node.end_lineno - 1][node.end_col_offset :]
    text = rest.split("#", 1)[1].strip() if "#" in rest else ""
    return text if _CLAIM_START.match(text) else None


def run_block(block: Block, namespace: dict[str, Any]) -> list[str]:
    """Run ``block`` statement by statement in ``namespace``; return the claims checked."""
    source = block.code
    checked = []
    for node in ast.parse(source).body:
        claim = _comment_of(source, node)
        segment = compile(ast.Module([node], []), f"README.md:{block.line}", "exec")
        if claim is None or not isinstance(node, ast.Expr):
            exec(segment, namespace)
            continue
        call = node.value
        if isinstance(call, ast.Call) and getattr(call.func, "id", "") == "print":
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(segment, namespace)
            actual = out.getvalue().strip()
        else:
            actual = repr(_plain(eval(compile(ast.Expression(call), "README", "eval"), namespace)))
        assert claim_holds(actual, claim), (
            f"README.md line {block.line + node.end_lineno}: shows {claim!r}, got {actual!r}"
        )
        checked.append(claim)
    return checked


def _marks(block: Block) -> list[Any]:
    return [pytest.mark.slow] if any(key in block.code for key in SLOW) else []


@pytest.mark.parametrize("block", [pytest.param(b, id=b.id, marks=_marks(b)) for b in PYTHON])
def test_python_block_runs_and_shows_what_it_computes(block, tmp_path, monkeypatch):
    """Each python block of the README runs as printed (after the blocks of its section it
    builds on), and each value its comments show is the value it computes."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))
    namespace: dict[str, Any] = {"__name__": "readme"}
    for earlier in prerequisites(block):
        with contextlib.redirect_stdout(io.StringIO()):
            run_block(earlier, namespace)
    with contextlib.redirect_stdout(io.StringIO()):
        run_block(block, namespace)


def commands() -> list[tuple[Block, str]]:
    """Every ``fcplan ...`` command line of the README's shell blocks (comments dropped,
    continuation lines joined)."""
    out = []
    for b in blocks():
        if b.lang not in ("", "bash", "sh", "console"):
            continue
        for line in b.code.replace("\\\n", " ").splitlines():
            cmd = " ".join(line.split(" #")[0].split())
            if cmd.startswith(("fcplan ", "SDL_VIDEODRIVER=dummy fcplan ")):
                out.append((b, cmd))
    return out


def _command_marks(cmd: str) -> list[Any]:
    return [pytest.mark.slow] if any(cmd.startswith(c) for c in SLOW_COMMANDS) else []


def _run_cli(cmd: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env_prefix, _, rest = cmd.rpartition("fcplan ")
    env = {**os.environ, **dict(kv.split("=", 1) for kv in env_prefix.split())}
    env["PYTHONPATH"] = str(ROOT)
    return subprocess.run(
        [sys.executable, "-m", "fcplan", *shlex.split(rest)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )


#: ``test_first_run_prints_the_output_shown`` runs the first command and checks its output.
FIRST = "fcplan run 12 --scheduler greedy --seed 0"
RUN = [(b, c) for b, c in commands() if c not in NOT_RUN and c != FIRST]


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """One scratch folder for the commands, which use each other's files (run.npz), with the
    docs/ inputs the README's commands read."""
    path = tmp_path_factory.mktemp("readme")
    (path / "docs").mkdir()
    (path / "docs" / "game_inputs.json").write_bytes((ROOT / "docs/game_inputs.json").read_bytes())
    return path


def test_every_command_runs_or_says_why_not():
    """Each ``fcplan`` command in the README is run by this file or listed with a reason."""
    listed = {c for _, c in commands()}
    assert set(NOT_RUN) <= listed, sorted(set(NOT_RUN) - listed)
    assert RUN


@pytest.mark.parametrize(
    "block, cmd", [pytest.param(b, c, id=c[:60], marks=_command_marks(c)) for b, c in RUN]
)
def test_command_runs_as_printed(block, cmd, workdir):
    """The command exits 0 from a scratch folder (the recording commands in README order)."""
    if "replay run.npz" in cmd and not (workdir / "run.npz").exists():
        assert _run_cli("fcplan run 1 -s greedy --record run.npz", workdir).returncode == 0
    p = _run_cli(cmd, workdir)
    assert p.returncode == 0, p.stderr


def _steady(text: str) -> str:
    """``fcplan run`` output without what depends on the machine (wall and solve times)."""
    text = re.sub(r"wall time [\d.]+ s", "wall time * s", text)
    return re.sub(r"solve p50 [\d.]+ ms, p95 [\d.]+ ms", "solve p50 * ms, p95 * ms", text)


def test_first_run_prints_the_output_shown():
    """``fcplan run 12 --scheduler greedy --seed 0``, the README's first command, prints the
    table shown under it, digit for digit (wall and solve times aside)."""
    bs = blocks()
    k = next(i for i, b in enumerate(bs) if "fcplan run 12 --scheduler greedy --seed 0" in b.code)
    shown = bs[k + 1].code
    p = _run_cli("fcplan run 12 --scheduler greedy --seed 0", ROOT)
    assert p.returncode == 0, p.stderr
    assert _steady(p.stdout).strip() == _steady(shown).strip()


def _prose() -> str:
    return re.sub(r"```.*?```", "", README.read_text(encoding="utf-8"), flags=re.DOTALL)


def test_fallbacks_without_the_reachable_mask(monkeypatch):
    """The README's count of the fallbacks the example scheduler makes without the
    ``reachable`` mask is what that variant makes on #12, seed 0."""
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))
    shown = int(re.search(r"falls back on (\d+) of the episode's replans", _prose()).group(1))
    (nearest,) = [b for b in PYTHON if "class Nearest" in b.code]
    masked = "np.where(graph.reachable[i], graph.agent_task_distance[i], np.inf)"
    assert masked in nearest.code
    code = nearest.code.replace(masked, "graph.agent_task_distance[i]")
    namespace: dict[str, Any] = {}
    exec(compile(code, "README.md", "exec"), namespace)
    assert namespace["result"].fallbacks == shown


def test_recording_size(tmp_path):
    """A 180-s episode of #24 recorded takes "about" the README's figure (within 25 %)."""
    from fcplan import run_episode

    shown = int(re.search(r"episode\s+of #24 takes about (\d+) KB", _prose()).group(1))
    path = tmp_path / "r.npz"
    run_episode(24, "greedy", seed=0, record=path)
    assert abs(path.stat().st_size / 1024 - shown) <= 0.25 * shown


def _section(title: str, level: str = "## ") -> str:
    """The README's section under the heading ``title`` (up to the next heading of its level)."""
    text = README.read_text(encoding="utf-8")
    section = text[text.index(f"\n{level}{title}") :]
    return section[: section.index(f"\n{level}", 1)]


def _assert_recorded(section: str) -> None:
    """Every figure of 100 or more in ``section`` (code aside) is within 1 % of a figure of
    bench/README.md."""
    section = re.sub(r"```.*?```|`[^`]*`", "", section, flags=re.DOTALL)
    recorded = [
        float(n.replace(",", ""))
        for n in re.findall(r"\d{1,3}(?:,\d{3})+|\d+", (ROOT / "bench/README.md").read_text())
    ]
    figures = [n for n in re.findall(r"\d{1,3}(?:,\d{3})+|\d{3,}", section)]
    assert figures
    for n in figures:
        value = float(n.replace(",", ""))
        if 2000 <= value <= 2100:  # a year
            continue
        assert any(abs(value - r) <= 0.01 * r for r in recorded), n


def test_benchmark_figures_are_recorded_in_bench_readme():
    """Every figure of the README's Benchmarks section (100 or more: rates, counts) is within
    1 % of a figure recorded in bench/README.md, so the README quotes measurements, not
    memories."""
    _assert_recorded(_section("Benchmarks"))


def test_batched_figures_are_recorded_in_bench_readme():
    """The batched environments' throughput table of the learning section quotes figures that
    bench/bench_vector.py printed into bench/README.md (world-steps per CPU second and MPE's
    steps in the same run)."""
    section = _section("Batched environments: many worlds per step", "### ")
    assert "| motion level, #1 |" in section
    _assert_recorded(section)


@pytest.mark.parametrize("path", ["README.md", "bench/README.md", *sorted(
    str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md"))])  # fmt: skip
def test_no_placeholder_is_left(path):
    """No line of the README, bench/README.md or the docs pages is a bare upper-case
    placeholder (``BATCHED_FIGURES``) waiting for a figure that was never filled in."""
    lines = (ROOT / path).read_text(encoding="utf-8").splitlines()
    left = [line for line in lines if re.fullmatch(r"[A-Z][A-Z0-9]*_[A-Z0-9_]+", line.strip())]
    assert not left, left


def test_study_example_is_as_large_as_the_readme_says(tmp_path):
    """The study.toml block is a valid sweep file of the size the text after it gives: 1,500
    episodes, 500 of them with routing."""
    from fcplan.experiments.config import load_sweep_config

    (block,) = [b for b in blocks() if b.lang == "toml" and "# study.toml" in b.code]
    path = tmp_path / "study.toml"
    path.write_text(block.code)
    episodes = load_sweep_config(path).episodes()
    m = re.search(
        r"This grid is ([\d,]+) episodes .*?([\d,]+) of them with `routing`", _prose(), re.S
    )
    total, routing = (int(g.replace(",", "")) for g in m.groups())
    assert len(episodes) == total
    assert sum(e.scheduler == "routing" for e in episodes) == routing


def test_notebooks_paragraph_names_every_notebook():
    """Each notebook in notebooks/ is named in the README's notebook paragraph."""
    text = _prose()
    paragraph = text[text.index("Notebooks in `notebooks/`") :].split("\n\n")[0]
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        assert f"`{path.stem}`" in paragraph, path.stem


def _caption_commands() -> list[str]:
    text = _prose()
    made = text[text.index("*Made with `fcplan run 20") :].split("*", 2)[1]
    return re.findall(r"`(fcplan [^`]+)`", made)


@pytest.mark.slow
def test_replay_gif_is_what_its_caption_makes(tmp_path):
    """docs/replay_20_greedy.gif is, frame for frame, what the caption's two commands write, and
    the episode does what the caption says: a fire unseen for about 40 s, out at about 90 s."""
    from PIL import Image, ImageSequence

    from fcplan.fire import BURNING
    from fcplan.recording import load_recording

    record, replay = _caption_commands()
    assert _run_cli(record, tmp_path).returncode == 0
    (tmp_path / "docs").mkdir()
    assert _run_cli(replay, tmp_path).returncode == 0
    made, shipped = (Image.open(d / "docs/replay_20_greedy.gif") for d in (tmp_path, ROOT))
    assert made.n_frames == shipped.n_frames
    for a, b in zip(ImageSequence.Iterator(made), ImageSequence.Iterator(shipped), strict=True):
        np.testing.assert_array_equal(np.asarray(a.convert("RGB")), np.asarray(b.convert("RGB")))
    frames = list(load_recording(tmp_path / "run.npz").frames(1, None, 10))
    burning = [f.tick for f in frames if (f.fire == BURNING).any()]
    run, longest = 0, 0  # longest stretch of seconds with fire burning and none of it known
    for f in frames:
        run = run + 1 if (f.fire == BURNING).any() and not f.known.any() else 0
        longest = max(longest, run)
    assert 35 <= longest <= 45 and 850 <= burning[-1] <= 950, (longest, burning[-1])


def test_caption_matches_the_gif():
    """The caption's command and alt text give the GIF's length: ``--end S`` at ``--speed 10``
    and 10 fps is S frames; the GIF's width is the map size plus the panel."""
    from PIL import Image

    from fcplan.render import panel_width

    replay = _caption_commands()[1]
    end, size = (int(re.search(rf"--{k} (\d+)", replay).group(1)) for k in ("end", "size"))
    assert re.search(rf"first {end} s at 10x speed", _prose())
    im = Image.open(ROOT / "docs/replay_20_greedy.gif")
    assert im.n_frames == end and im.size == (size + panel_width(size), size)


def test_random_motion_score_in_the_comment():
    """The random-legal-moves score the PlanFollower block's comment quotes is that of random
    legal moves (seeded as the motion block above it) on the same scenario and seed."""
    from fcplan.env.motion import MotionEnv

    (block,) = [b for b in PYTHON if "PlanFollower(env" in b.code]
    shown = float(re.search(r"random legal moves: (-?[\d.]+)", block.code).group(1))
    env = MotionEnv(1)
    obs, infos = env.reset(seed=0)
    rng = np.random.default_rng(0)
    while env.agents:
        actions = {a: rng.choice(np.flatnonzero(obs[a]["action_mask"])) for a in env.agents}
        obs, rewards, terms, truncs, infos = env.step(actions)
    assert claim_holds(str(infos["P1"]["metrics"]["manual"]["final_score"]), f"{shown}")


def test_simulation_facts_are_the_code_s():
    """The numbers of "Simulation in brief" and "Play it yourself" are the code's: 10 Hz,
    sensing confidence 100 % to 40 %, 90 % pruning for action agents, 3 s before an idle action
    agent goes home, 5 m per altitude step, a patrol closed within 100 px at 20 px per tick."""
    from fcplan import load_scenario
    from fcplan.game.controls import ALTITUDE_STEP, PATROL_RADIUS_STEPS
    from fcplan.scenario import Role
    from fcplan.team import ACTION_IDLE_LIMIT_S, sensing_confidence

    text = _prose()
    for fact in ("fixed tick of 10 Hz", "100% at the lowest altitude and 40% at the",
                 "(90% for action agents, 80% for hybrids)", "hovering 3 s at its last goal",
                 "altitude by 5 m", "within 100 px of the route's first goal"):  # fmt: skip
        assert fact in " ".join(text.split()), fact
    assert load_scenario(12).ticks_per_second == 10
    assert sensing_confidence(np.array([10.0, 100.0]), 10.0, 100.0).round(6).tolist() == [1, 0.4]
    actions = [a for a in load_scenario(12).agents if a.role is Role.ACTION]
    assert actions and all(a.prune_confidence == 0.9 for a in actions)
    assert ACTION_IDLE_LIMIT_S == 3.0 and ALTITUDE_STEP == 5.0
    assert PATROL_RADIUS_STEPS * 20 == 100
