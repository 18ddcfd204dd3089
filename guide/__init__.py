"""The lab's guide (issue 22): a MkDocs + Material site built from docs/ into web/guide/.

How the built site reaches a user: it is **committed** under web/guide/, like the JS bundles in
web/static/, so the wheel carries it (package-data of `server.web_assets`, the link to web/) and
`robodojo serve` from a fresh install serves it at /guide/ with no MkDocs, Node or network on the
lab's machine. `python3 -m guide.build` rebuilds it; `python3 -m guide.build --check` (a test of
the suite) rebuilds into a temporary folder in strict mode and fails when the committed copy
differs, so a page changed without a rebuild never lands. The build is deterministic for the
pinned MkDocs, Material, pymdown-extensions, Markdown and Pygments versions (pyproject's test
extra): nothing in it depends on the date or the machine (the sitemap, which carries the build
date, is not written).

Parts: `hooks.py` (MkDocs hooks: generated sections, scripts moved out of the pages for the
lab's Content-Security-Policy), `settings_table.py`, `api_reference.py`, `catalog_tables.py`
(what is generated from the code, never written twice), `build.py` (the command), `samples.py`
(the controllers in the student pages, which a test runs in the sandbox), `figures.py` (the
screenshots and plots, `python3 -m guide.figures`).
"""
