"""The documentation as a reader meets it: every link and anchor resolves, every "docs/X.md
section N" names a section that exists, every topic has a heading, and the docs speak of the
product as it is, not of how it was made."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = sorted((ROOT / "docs").glob("*.md"))
PAGES = [ROOT / "README.md", *DOCS]


def _prose(text: str) -> list[tuple[int, str]]:
    """(line number, line) of the lines outside fenced code blocks."""
    out, fence = [], False
    for n, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fence = not fence
            continue
        if not fence:
            out.append((n, line))
    return out


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _headings(page: Path) -> list[tuple[int, int, str]]:
    """(line number, level, text) of every heading of a page."""
    return [(n, len(m.group(1)), m.group(2)) for n, line in _prose(page.read_text())
            if (m := re.match(r"^(#{1,6}) (.+?)\s*$", line))]


def _anchors(page: Path) -> set[str]:
    seen: dict[str, int] = {}
    out = set()
    for _, _, text in _headings(page):
        s = _slug(text)
        out.add(s if s not in seen else f"{s}-{seen[s]}")
        seen[s] = seen.get(s, 0) + 1
    return out


def _links(page: Path) -> list[tuple[int, str]]:
    """(line number, target) of every relative Markdown link of a page."""
    out = []
    for n, line in _prose(page.read_text()):
        for target in re.findall(r"\]\(([^)\s]+)\)", line):
            if not re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
                out.append((n, target))
    return out


def _section_numbers(page: Path) -> set[str]:
    """The numbers of a page's numbered headings: '6', '6.2', ..."""
    return {m.group(1) for _, _, text in _headings(page) if (m := re.match(r"(\d+(?:\.\d+)*)\.? ", text))}


def test_the_link_check_sees_links_and_anchors():
    """The checker itself: it finds this page's links and GitHub's anchors of odd headings."""
    assert _slug("6. Step control (`technique = 'newmark'`, `fd_newmark.f90`)") == (
        "6-step-control-technique--newmark-fd_newmarkf90")
    assert _slug("Does dt1 resolve a record?") == "does-dt1-resolve-a-record"
    assert len([t for p in PAGES for _, t in _links(p)]) > 50
    assert "65-mode-resolution-does-dt1-resolve-the-highest-modes" in _anchors(ROOT / "docs/theory.md")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_relative_link_and_anchor_resolves(page):
    bad = []
    for n, target in _links(page):
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            bad.append(f"{page.name}:{n}: {target}: no such file")
        elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
            bad.append(f"{page.name}:{n}: {target}: no such heading")
    assert not bad, "\n".join(bad)


# "docs/theory.md section 6", "docs/theory.md, section 5.4", "docs/theory.md 5.4",
# "docs/studies.md, 3.2", "docs/theory.md, sections 6 and 12", "docs/validation.md, 6.4"
REF = re.compile(r"docs/(\w+)\.md(?:'s)?,? (?:sections? )?(\d+(?:\.\d+)*)((?:(?:, | and )\d+(?:\.\d+)*)*)")
SOURCES = ["README.md", "docs", "fortran", "driver", "tests", "tools", "bench", "inputs"]


def _files_that_cite_docs():
    for entry in SOURCES:
        base = ROOT / entry
        for f in [base] if base.is_file() else sorted(base.rglob("*")):
            if f.is_file() and f.suffix in {".md", ".py", ".f90", ".F90", ".c", ".sh", ".nml", ".build"}:
                yield f


def test_every_numbered_section_a_file_cites_exists():
    """A comment, message, test or page that cites "docs/<page>.md section N" points at a
    section that is there (renumbering a page breaks this test, not the reader)."""
    numbers = {p.stem: _section_numbers(p) for p in DOCS}
    bad, seen = [], 0
    for f in _files_that_cite_docs():
        text = re.sub(r"\s*\n\s*(?:!>?|#|//|\*)?\s*", " ", f.read_text(errors="replace"))
        for m in REF.finditer(text):
            page = m.group(1)
            if page not in numbers:
                continue
            for num in [m.group(2), *re.findall(r"\d+(?:\.\d+)*", m.group(3))]:
                seen += 1
                if num not in numbers[page]:
                    bad.append(f"{f.relative_to(ROOT)}: docs/{page}.md section {num}")
    assert seen > 50
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("page", [p for p in PAGES if p.name != "architecture.md"], ids=lambda p: p.name)
def test_no_section_runs_long_without_a_heading(page):
    """Every topic has a heading: no more than 80 lines of a page without one."""
    lines = page.read_text().splitlines()
    starts = [n for n, _, _ in _headings(page)] + [len(lines) + 1]
    longest = max(b - a for a, b in zip([1, *starts], starts))
    assert longest <= 80


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_docs_speak_of_the_product_not_of_its_making(page):
    text = page.read_text()
    for pattern in [r"\bstops? \d+\b", r"\bissues? \d+\b", r"\bsince the last change\b",
                    r"\bprevious stop\b", r"\bthis version\b"]:
        assert not re.search(pattern, text, re.I), (page.name, pattern)


def _cells(page: Path) -> list[tuple[int, str]]:
    """(line number, text) of every table cell of a page ('\\|' is a pipe inside a cell)."""
    return [(n, cell.strip()) for n, line in _prose(page.read_text()) if line.startswith("|")
            for cell in re.split(r"(?<!\\)\|", line)[1:-1]]


def test_the_namelist_tables_hold_short_cells():
    """A variable's row is its meaning, unit, default and range; the long explanations are the
    notes below the table, which the row links."""
    page = ROOT / "docs/namelist.md"
    long = [(n, len(c)) for n, c in _cells(page) if len(c) > 300]
    assert not long
    notes = {a for a in _anchors(page) if a.startswith("note-")}
    linked = {t[1:] for _, t in _links(page) if t.startswith("#note-")}
    assert len(notes) >= 20 and notes == linked


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_no_table_cell_is_a_page_of_its_own(page):
    assert max((len(c) for _, c in _cells(page)), default=0) <= 1000


# --- the README a new user reads ------------------------------------------------------------

def _blocks(page: Path, lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", page.read_text(), re.M | re.S)


def test_the_readme_reads_in_two_minutes():
    text = (ROOT / "README.md").read_text()
    first = re.search(r"^# frictiondyn\n\n(.+?\.)(?:\s|$)", text, re.S).group(1)
    assert len(first.split()) <= 20, first
    assert len(re.sub(r"```.*?```", "", text, flags=re.S).split()) <= 600


def test_the_readmes_quick_start_is_what_ci_runs():
    """The two quick-start commands are the set-up-and-run script (its default deck the one
    the README names) and the test script that .ci/run runs."""
    (quick, *_) = _blocks(ROOT / "README.md", "sh")
    assert [line.split()[0] for line in quick.splitlines()] == ["tools/run.sh", "tools/test.sh"]
    assert "inputs/test4_velocity.nml" in quick
    assert "deck=${1:-inputs/test4_velocity.nml}" in (ROOT / "tools/run.sh").read_text()
    assert re.search(r"^bash tools/test\.sh\b", (ROOT / ".ci/run").read_text(), re.M)
    assert "bash tools/setup.sh" in (ROOT / "tools/test.sh").read_text()


def test_the_readmes_deck_runs_and_slides():
    """The example deck (at most 10 lines) runs as printed: the table's peak acceleration,
    (2 pi 2 Hz)^2 x 10 mm = 1.58 m/s2, is above mu g = 0.98 m/s2, so the mass slides."""
    import frictiondyn as fd

    (deck,) = _blocks(ROOT / "README.md", "fortran")
    assert len(deck.splitlines()) <= 10
    s = fd.run_text(deck, name="slider.nml").summary
    assert s["stick_to_slip"][0] > 0 and s["warnings"] == []
    assert s["correctness_violations"] == 0


def test_the_readmes_python_example_prints_what_it_says(tmp_path, monkeypatch, capsys):
    """The five lines run as printed, and each print gives what its comment shows."""
    (code,) = _blocks(ROOT / "README.md", "python")
    assert len(code.splitlines()) <= 5
    (tmp_path / "inputs").symlink_to(ROOT / "inputs")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    printed = capsys.readouterr().out.splitlines()
    said = [re.sub(r"\s*m/s2$", "", line.split("#", 1)[1].strip())
            for line in code.splitlines() if line.startswith("print(")]
    assert len(printed) == len(said) == 2
    for out, comment in zip(printed, said):
        assert re.fullmatch(re.escape(comment).replace(r"\.\.\.", r"\d*"), out), (out, comment)
    assert (tmp_path / "test4_velocity.csv").stat().st_size > 0


# --- figures the docs quote that the code produces ------------------------------------------

def _ref(deck: str) -> dict:
    return json.loads((ROOT / "tests/reference" / f"{deck}.summary.json").read_text())


def _flat(page: str) -> str:
    return re.sub(r"\s+", " ", (ROOT / page).read_text())


def _quoted(page: str, *figures: str):
    text = _flat(page)
    missing = [f for f in figures if f not in text]
    assert not missing, (page, missing)


def test_the_counts_the_docs_quote():
    """Unit suites, bundled decks and their references, deck groups and variables."""
    build = (ROOT / "tests/unit/meson.build").read_text()
    suites = re.findall(r"^\s+'(\w+)',$", build.split("unit_suites = [")[1].split("]")[0], re.M)
    decks = sorted(p.stem for p in (ROOT / "inputs").glob("*.nml"))
    references = sorted(p.name.removesuffix(".summary.json")
                        for p in (ROOT / "tests/reference").glob("*.summary.json"))
    assert decks == references
    _quoted("README.md", f"the {len(suites)} Fortran unit suites, the {len(decks)} bundled decks")
    src = re.sub(r"&[ \t]*\n[ \t]*&?", " ", (ROOT / "fortran/io/fd_deck.f90").read_text())
    groups = {m[1]: m[2].split(",") for m in re.finditer(r"namelist\s*/(\w+)/([^\n!]*)", src, re.I)}
    _quoted("docs/namelist.md", f"A deck has {len(groups)} groups of "
            f"{sum(len(v) for v in groups.values())} variables in all")


def test_the_paper_figures_the_theory_and_studies_quote():
    """Counts and values of the bundled decks that theory.md, studies.md and python.md quote,
    against the reference outputs (regenerating those makes this test say what moved)."""
    v4, h4, c4 = _ref("test4_velocity"), _ref("test4_hysteretic"), _ref("test4_coulomb")
    v3, h3, fps = _ref("test3_velocity"), _ref("test3_hysteretic"), _ref("isolated_fps")

    def n(x: int) -> str:  # 41524 -> "41 524"
        return f"{x:,}".replace(",", " ")

    _quoted("docs/theory.md",
            f"T = 2 pi sqrt(8.831 / 3979) = {v4['period_stuck_s']:.5f} s",
            f"factors twice in 40 s (dt1 and dt2) and updates {v4['factor_updates']} times (each of its "
            f"{v4['stick_to_slip'][0] + v4['slip_to_stick'][0]} phase changes",
            f"on test 4 the hysteretic law counts {h4['stick_to_slip'][0]} stick-to-slip transitions in "
            f"40 s, the velocity law {v4['stick_to_slip'][0]}; on test 3, {h3['stick_to_slip'][0]} "
            f"against {v3['stick_to_slip'][0]}",
            f"takes {n(fps['mu_passes'])} passes for its {n(fps['steps_dt1'] + fps['steps_dt2'])} steps",
            f"the transitions equal the exact technique's "
            f"({c4['stick_to_slip'][0] + c4['slip_to_stick'][0]} in 40 s)",
            f"{abs(c4['energy_residual_J']):.0e} J of {c4['energy_input_J']:.0f} J on test 4")
    assert v4["factorizations"] == 2
    _quoted("docs/studies.md",
            f"against {h4['stick_to_slip'][0]} stops",
            f"against {_ref('building5_friction')['stick_to_slip']}",
            f"{n(h4['steps_dt2'])} dt2 steps become",
            f"the same {h4['stick_to_slip'][0]} transitions",
            f"{c4['events']} events, {c4['factorizations']} patterns")
    peaks = v4["peak_aabs_mps2"]
    cut4 = [f"{int(x * 1e4) / 1e4:.4f}..." for x in peaks]  # printed to 4 places, then "..."
    _quoted("docs/python.md", f"[{cut4[0]}, {cut4[1]}] m/s2",
            f"[{v4['stick_to_slip'][0]}] {v4['correctness_violations']}")


def test_the_worked_examples_quote_their_reference_outputs():
    """docs/examples.md: the numbers 'the scripts print (and tests/reference/ holds)'."""
    bare, damped, fps = _ref("building5_bare"), _ref("building5_dampers"), _ref("isolated_fps")
    g = 9.81

    def periods(p):
        return ", ".join(f"{x:.3f}" for x in p)

    rows = [f"| {s + 1} | {100 * b:.3f} % | {100 * d:.3f} % | {1000 * r:.3f} mm |".replace("| -0.", "| -0.")
            for s, (b, d, r) in enumerate(zip(bare["peak_drift_ratio"], damped["peak_drift_ratio"],
                                              damped["residual_drift_m"]))]
    cut = [1 - d / b for b, d in zip(bare["peak_drift_ratio"], damped["peak_drift_ratio"])]
    _quoted("docs/examples.md",
            f"the bare frame {periods(bare['periods_free_s'])} s",
            f"with the dampers stuck (braces elastic) {periods(damped['periods_stuck_s'])} s",
            f"`damping_a0_per_s` = {damped['damping_a0_per_s']:.4f} 1/s",
            f"`damping_a1_s` = {damped['damping_a1_s'] * 1e4:.2f}e-4 s",
            *rows,
            f"by {100 * min(cut):.0f} to {100 * max(cut):.0f} %",
            f"from {bare['peak_aabs_mps2'][-1] / g:.3f} g to {damped['peak_aabs_mps2'][-1] / g:.3f} g",
            f"from {bare['peak_base_shear_N'] / 1e3:.0f} kN to {damped['peak_base_shear_N'] / 1e3:.0f} kN",
            f"they dissipate {100 * damped['energy_friction_J'] / damped['energy_input_J']:.0f} %",
            f"the frame on a fixed base, {periods(fps['periods_stuck_s'])} s",
            f"the isolation mode {fps['periods_free_s'][0]:.3f} s",
            f"the frame's {periods(fps['periods_free_s'][1:])} s",
            " / ".join(f"{100 * r:.3f}" for r in fps["peak_drift_ratio"][1:]) + " %",
            f"| {fps['peak_aabs_mps2'][-1] / g:.3f} g |",
            f"| {1000 * fps['peak_s_m'][0]:.1f} mm |",
            f"residual of {1000 * abs(fps['residual_s_m'][0]):.1f} mm")


def test_the_single_node_slurm_conf_shown_is_the_tested_one():
    """docs/batch.md shows tools/slurm/single-node.conf.in whole, the file the Slurm test
    runs."""
    conf = (ROOT / "tools" / "slurm" / "single-node.conf.in").read_text()
    assert "```\n" + conf + "```" in (ROOT / "docs" / "batch.md").read_text()
