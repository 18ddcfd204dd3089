"""MkDocs hooks of the guide (mkdocs.yml `hooks:`), run by every build:

- `<!-- generated: NAME [ARG] -->` in a page is replaced by what the code says now (the settings
  table, the API reference, a robot's topics, an exercise's checks). An unknown NAME fails the
  build with a sentence, so a typo never ships an empty section.
- Every inline `<script>` Material writes is moved to a file under `assets/inline/` named by its
  content hash: the lab serves the guide under its Content-Security-Policy (`script-src 'self'`,
  server/api/http_guards.py), which would block inline scripts.
- The sitemap (it carries the build date) and the assets the lab never uses (source maps, the
  search index's other languages) are removed, so a rebuild of unchanged pages is byte-identical
  and `python3 -m guide.build --check` can compare it with the committed copy.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import sys
from collections.abc import Callable
from pathlib import Path
from urllib.parse import urlsplit

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # `mkdocs build` run directly puts only its own folder there
    sys.path.insert(0, str(ROOT))

from mkdocs.exceptions import PluginError  # noqa: E402

from guide import api_reference, catalog_tables, ros_sentences, settings_table  # noqa: E402

DIRECTIVE = re.compile(r"<!--\s*generated:\s*([a-z-]+)\s*([^\s>]*)\s*-->")
INLINE_SCRIPT = re.compile(r"<script>(.*?)</script>", re.DOTALL)
CANONICAL = re.compile(r'\s*<link rel="canonical" href="[^"]*">')
INLINE_DIR = "assets/inline"
UNUSED = (
    "sitemap.xml",
    "sitemap.xml.gz",
    "assets/javascripts/lunr",  # languages other than English
)

GENERATORS: dict[str, Callable[[str], str]] = {
    "settings-table": lambda _: settings_table.settings_markdown(),
    "api-reference": lambda _: api_reference.api_markdown(),
    "robot": catalog_tables.robot_markdown,
    "exercise": catalog_tables.exercise_markdown,
    "exercise-text": catalog_tables.exercise_text,
    "migrations": lambda _: catalog_tables.migrations_markdown(),
    "grades-columns": lambda _: catalog_tables.grades_columns_markdown(),
    "generic-checks": lambda _: catalog_tables.generic_checks_markdown(),
    "ros-sentences": ros_sentences.sentences_markdown,
}

_scripts: dict[str, str] = {}  # file name -> script text, for on_post_build


class GuideError(PluginError):
    """A mistake in a page's generated section: MkDocs stops the build with this sentence."""


def on_page_markdown(markdown: str, page, config, files) -> str:
    def expand(match: re.Match) -> str:
        name, argument = match.group(1), match.group(2)
        generator = GENERATORS.get(name)
        if generator is None:
            raise GuideError(
                f"{page.file.src_path}: unknown generated section '{name}'; "
                f"known: {', '.join(GENERATORS)}"
            )
        try:
            return generator(argument)
        except (KeyError, ValueError) as error:
            where = f"{page.file.src_path}: generated: {name} {argument}"
            raise GuideError(f"{where}: {error}") from error

    return DIRECTIVE.sub(expand, markdown)


def _without_inline_scripts(output: str, to_root: str) -> str:
    def move(match: re.Match) -> str:
        script = match.group(1)
        name = hashlib.sha256(script.encode()).hexdigest()[:16] + ".js"
        _scripts[name] = script
        return f'<script src="{to_root}{INLINE_DIR}/{name}"></script>'

    return CANONICAL.sub("", INLINE_SCRIPT.sub(move, output))


def on_post_page(output: str, page, config) -> str:
    return _without_inline_scripts(output, "../" * page.url.count("/"))


def on_post_template(output: str, template_name: str, config) -> str:
    """404.html: served for a missing page at any depth, so its links are absolute."""
    return _without_inline_scripts(output, urlsplit(config["site_url"]).path)


def on_post_build(config) -> None:
    site = Path(config["site_dir"])
    inline = site / INLINE_DIR
    inline.mkdir(parents=True, exist_ok=True)
    for name, script in sorted(_scripts.items()):
        (inline / name).write_text(script)
    _scripts.clear()
    for name in UNUSED:
        target = site / name
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
    for source_map in site.glob("assets/**/*.map"):
        source_map.unlink()
