"""Build the guide in strict mode into web/guide/ (committed; served at /guide/).

    python3 -m guide.build            # rebuild web/guide/ from docs/ and the code
    python3 -m guide.build --check    # exit 1 when web/guide/ is not what docs/ builds now
    python3 -m guide.build --out DIR  # a static copy anywhere (any web server can serve it)

Strict: a broken link, a link to a missing anchor, a page left out of the nav or an unknown
generated section fails the build with MkDocs' message. ~10 s on the 2-core machine.
"""

from __future__ import annotations

import argparse
import filecmp
import logging
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "mkdocs.yml"
COMMITTED = ROOT / "web" / "guide"


class BuildFailed(Exception):
    pass


class _Collect(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage())


def build(out: Path) -> None:
    """The site into `out` (replaced), strict: any MkDocs warning is a BuildFailed."""
    from mkdocs.commands.build import build as mkdocs_build
    from mkdocs.config import load_config
    from mkdocs.exceptions import Abort, MkDocsException

    collect = _Collect()
    mkdocs_log = logging.getLogger("mkdocs")
    mkdocs_log.addHandler(collect)
    try:
        try:
            config = load_config(str(CONFIG), site_dir=str(out), strict=True)
            mkdocs_build(config)
        except (Abort, MkDocsException) as error:
            details = "\n  ".join(collect.messages)
            raise BuildFailed(f"the guide does not build: {error}\n  {details}") from error
    finally:
        mkdocs_log.removeHandler(collect)
    if collect.messages:
        raise BuildFailed("the guide built with warnings:\n  " + "\n  ".join(collect.messages))


def differences(left: Path, right: Path) -> list[str]:
    """Relative paths that differ between two trees (missing on either side or other bytes)."""
    found: list[str] = []

    def walk(compare: filecmp.dircmp, prefix: str) -> None:
        for name in compare.left_only + compare.right_only + compare.funny_files:
            found.append(prefix + name)
        _, mismatch, errors = filecmp.cmpfiles(
            compare.left, compare.right, compare.common_files, shallow=False
        )
        found.extend(prefix + name for name in mismatch + errors)
        for name, sub in compare.subdirs.items():
            walk(sub, f"{prefix}{name}/")

    walk(filecmp.dircmp(left, right), "")
    return sorted(found)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m guide.build", description=__doc__)
    parser.add_argument("--check", action="store_true", help="compare with web/guide/ only")
    parser.add_argument("--out", type=Path, default=None, help="build here instead")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="robodojo-guide-") as temporary:
        built = Path(temporary) / "site"
        try:
            build(built)
        except BuildFailed as error:
            print(error, file=sys.stderr)
            return 1
        if args.check:
            changed = differences(built, COMMITTED) if COMMITTED.is_dir() else ["(all of it)"]
            if changed:
                print(
                    f"web/guide/ is not what docs/ builds now ({len(changed)} files differ: "
                    f"{', '.join(changed[:8])}{' ...' if len(changed) > 8 else ''}); run "
                    "python3 -m guide.build and commit web/guide/",
                    file=sys.stderr,
                )
                return 1
            print("web/guide/ is up to date")
            return 0
        target = args.out or COMMITTED
        if target.exists():
            shutil.rmtree(target)
        shutil.copytree(built, target)
        print(f"the guide is in {target}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
