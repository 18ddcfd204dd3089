"""The guide's build (issue 22): strict (a broken link, a page left out of the nav or an unknown
generated section fails it), deterministic, and the committed web/guide/ is what docs/ builds."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from guide import build
from guide.api_reference import api_markdown
from guide.settings_table import settings_markdown
from server.api.app import create_app
from server.api.settings import Settings

ROOT = Path(__file__).resolve().parents[2]
COMMITTED = ROOT / "web" / "guide"


def test_the_committed_guide_is_what_the_docs_build(capsys):
    assert build.main(["--check"]) == 0, capsys.readouterr().err


def _tiny_site(tmp_path: Path, pages: dict[str, str], nav: list) -> Path:
    """The real mkdocs.yml (theme, validation, hooks) over a few pages of the test's own."""
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    docs = tmp_path / "docs"
    for name, text in pages.items():
        (docs / name).parent.mkdir(parents=True, exist_ok=True)
        (docs / name).write_text(text)
    config.update(docs_dir=str(docs), nav=nav, hooks=[str(ROOT / "guide" / "hooks.py")])
    config.pop("exclude_docs", None)
    path = tmp_path / "mkdocs.yml"
    path.write_text(yaml.safe_dump(config))
    return path


@pytest.mark.parametrize(
    ("pages", "nav", "said"),
    [
        ({"index.md": "# Home\n\n[gone](missing.md)\n"}, ["index.md"], "missing.md"),
        ({"index.md": "# Home\n\n[anchor](#nowhere)\n"}, ["index.md"], "nowhere"),
        ({"index.md": "# Home\n", "lost.md": "# Lost\n"}, ["index.md"], "lost.md"),
        (
            {"index.md": "# Home\n\n<!-- generated: setting-table -->\n"},
            ["index.md"],
            "unknown generated section 'setting-table'",
        ),
        ({"index.md": "# Home\n\n<!-- generated: robot crowbto -->\n"}, ["index.md"], "crowbto"),
    ],
    ids=["broken link", "missing anchor", "page not in nav", "unknown section", "unknown robot"],
)
def test_a_mistake_in_the_docs_fails_the_build_saying_where(tmp_path, monkeypatch, pages, nav,
                                                            said):  # fmt: skip
    monkeypatch.setattr(build, "CONFIG", _tiny_site(tmp_path, pages, nav))
    with pytest.raises(build.BuildFailed) as failure:
        build.build(tmp_path / "site")
    assert said in str(failure.value)


def test_a_clean_tiny_site_builds(tmp_path, monkeypatch):
    pages = {"index.md": "# Home\n\n[next](next.md)\n", "next.md": "# Next\n"}
    monkeypatch.setattr(build, "CONFIG", _tiny_site(tmp_path, pages, ["index.md", "next.md"]))
    build.build(tmp_path / "site")
    assert (tmp_path / "site" / "next" / "index.html").is_file()


def test_no_built_page_holds_an_inline_script():
    """The lab's CSP (script-src 'self') would block them: the hooks move them to files."""
    pages = list(COMMITTED.rglob("*.html"))
    assert len(pages) > 20
    for page in pages:
        for tag in re.findall(r"<script\b[^>]*>", page.read_text()):
            assert "src=" in tag or 'type="application/json"' in tag, (page, tag)


def test_no_built_file_carries_the_build_date_or_a_source_map():
    assert not (COMMITTED / "sitemap.xml").exists()
    assert not list(COMMITTED.rglob("*.map"))


def test_the_settings_table_names_every_setting_once():
    table = settings_markdown()
    for name in Settings.model_fields:
        assert table.count(f"| `ROBODOJO_{name.upper()}`") == 1, name


def test_the_settings_table_takes_units_and_reasons_from_the_code():
    table = settings_markdown()
    row = next(line for line in table.splitlines() if "`ROBODOJO_MAX_RUN_DURATION_S`" in line)
    assert "| s |" in row and "ten minutes of robot time" in row and "`600.0`" in row
    row = next(line for line in table.splitlines() if "`ROBODOJO_MAX_REQUEST_BODY_BYTES`" in line)
    assert "4 MiB" in row and "before login" in row  # the comment's continuation line too
    row = next(line for line in table.splitlines() if "`ROBODOJO_HOST`" in line)
    assert "`--host`" in row and "address to listen on" in row  # no comment: the option's help


def test_the_api_reference_has_every_operation():
    spec = create_app().openapi()
    reference = api_markdown(spec)
    for path, operations in spec["paths"].items():
        for method in operations:
            assert f"### `{method.upper()} {path}`" in reference
    built = (COMMITTED / "reference" / "api" / "index.html").read_text()
    assert "/api/runs/{run_id}/estop" in built


def test_every_robot_and_exercise_has_its_section_and_figure():
    """A robot or exercise added to a registry and not to the guide fails here."""
    from server.exercises.registry import exercise_ids
    from server.sim.registry import robot_ids

    docs = ROOT / "docs"
    robots = (docs / "students" / "robots.md").read_text()
    exercises = (docs / "students" / "exercises.md").read_text()
    for robot in robot_ids():
        assert f"<!-- generated: robot {robot} -->" in robots, robot
        assert (docs / "images" / "robots" / f"{robot}.png").is_file(), robot
    for exercise in exercise_ids():
        assert f"<!-- generated: exercise {exercise} -->" in exercises, exercise
        assert (docs / "images" / "exercises" / f"{exercise}.png").is_file(), exercise
