"""The docs name what exists: every module, file and dotted name docs/architecture.md gives
(`benchmark/camera/optics.py`, `benchmark.camera.optics`, `optics.channel_signal`, the
house's module lists) is in the source, and every link or quoted section name that points at
a heading of a page under docs/ (`docs/performance.md#bytes-across-machines`,
docs/results.md, "Acceptance checks") finds it. Read from the text and the source (ast); no
module is imported."""

import ast
import functools
import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"
ARCHITECTURE = DOCS / "architecture.md"
PACKAGES = ("metricscenes", "benchmark")
FILE_SUFFIXES = {"yaml", "yml", "json", "jsonl", "csv", "lock", "png", "svg", "h5", "hdf5", "html", "npz", "txt", "md",
                 "py", "sh", "env", "onnx", "zarr", "started"}


# --- the source --------------------------------------------------------------------------------------------


def _module_file(dotted: str) -> Path | None:
    """The file of module or package ``dotted`` (``benchmark.camera.optics``), None if there is none."""
    base = REPO.joinpath(*dotted.split("."))
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    return None


@functools.cache
def _names(path: Path) -> tuple[frozenset[str], dict[str, frozenset[str]]]:
    """A module's top-level names (definitions, assignments, imports) and each class's members."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))

    def assigned(body) -> set[str]:
        out = set()
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                out.add(node.name)
            elif isinstance(node, ast.Assign):
                out.update(t.id for t in node.targets if isinstance(t, ast.Name))
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                out.add(node.target.id)
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                out.update((a.asname or a.name).split(".")[0] for a in node.names)
            elif isinstance(node, (ast.If, ast.Try)):  # guarded imports and definitions
                out.update(assigned(node.body))
                out.update(assigned(getattr(node, "orelse", [])))
                for handler in getattr(node, "handlers", []):
                    out.update(assigned(handler.body))
        return out

    classes = {node.name: frozenset(assigned(node.body)) for node in tree.body if isinstance(node, ast.ClassDef)}
    return frozenset(assigned(tree.body)), classes


@functools.cache
def _modules() -> tuple[str, ...]:
    """Every module and package of the two packages, dotted."""
    out = []
    for package in PACKAGES:
        for path in (REPO / package).rglob("*.py"):
            parts = path.relative_to(REPO).with_suffix("").parts
            out.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return tuple(sorted(out))


def _resolves(dotted: str) -> bool:
    """``dotted`` is a module, or a module's top-level name, or a member of one of its classes."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        path = _module_file(".".join(parts[:i]))
        if path is None:
            continue
        rest = parts[i:]
        if not rest:
            return True
        top, classes = _names(path)
        if rest[0] not in top:
            return False
        return len(rest) == 1 or rest[0] not in classes or rest[1] in classes[rest[0]]
    return False


def _problem(dotted: str) -> str | None:
    """Why a dotted name in the docs does not name the source (None where it does, or where it
    names no module of ours: ``Collection.radiance``, ``manifest.resolved.yaml``)."""
    parts = dotted.split(".")
    if parts[-1] in FILE_SUFFIXES:
        return None
    if parts[0] in PACKAGES:
        return None if _resolves(dotted) else f"{dotted}: no such module or name"
    candidates = [m for m in _modules() if m.split(".")[-1] == parts[0]]
    if not candidates or any(_resolves(".".join([m, *parts[1:]])) for m in candidates):
        return None
    return f"{dotted}: not in {', '.join(candidates)}"


# --- docs/architecture.md ----------------------------------------------------------------------------------

PATH = re.compile(r"(?<![\w/.-])((?:metricscenes|benchmark|benchmarks|tests|docs|manifests|cameras|examples)/[\w./-]*\w/?)")
DOTTED = re.compile(r"^\.?([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+)(?:\(.*\))?$")


def _code_spans(text: str) -> list[str]:
    text = re.sub(r"```.*?```", "", text, flags=re.S)
    return re.findall(r"`([^`\n]+)`", text)


def _house_block(text: str) -> list[str]:
    """The lines of the code block under "## The house"."""
    section = text.split("## The house", 1)[1]
    return section.split("```", 2)[1].splitlines()


HOUSE_LINE = re.compile(r"^( {0,4})([a-z_][a-z0-9_]*/?(?:, [a-z_][a-z0-9_]*/?)*)(?: {2,}.*)?$")


def architecture_problems(text: str) -> list[str]:
    """Everything docs/architecture.md (``text``) names that the repository lacks."""
    problems = []
    for path in sorted(set(PATH.findall(text))):
        if "<" in path or "*" in path:
            continue
        if not (REPO / path.rstrip("/")).exists():
            problems.append(f"{path}: no such file or folder")
    dotted = {m.group(1) for span in _code_spans(text) if (m := DOTTED.match(span.strip()))}
    dotted |= set(re.findall(r"\b((?:metricscenes|benchmark)(?:\.[A-Za-z_]\w*)+)", text))
    problems += [p for name in sorted(dotted) if (p := _problem(name))]
    top = sub = None
    for line in _house_block(text):
        m = HOUSE_LINE.match(line)
        if not m or len(m.group(1)) not in (0, 2, 4):
            continue
        indent, names = len(m.group(1)), m.group(2).split(", ")
        if indent == 0:
            top, sub = names[0].rstrip("/"), None
            if not (REPO / top).is_dir():
                problems.append(f"house: {top}/: no such folder")
            continue
        if top not in PACKAGES or (indent == 4 and sub is None):
            continue
        parent = top if indent == 2 else f"{top}.{sub}"
        for name in names:
            if name.endswith("/"):
                if _module_file(f"{parent}.{name[:-1]}") is None:
                    problems.append(f"house: {parent.replace('.', '/')}/{name}: no such package")
                if indent == 2:
                    sub = name[:-1]
            elif _module_file(f"{parent}.{name}") is None:
                problems.append(f"house: {parent}.{name}: no such module")
        if indent == 2 and not names[-1].endswith("/"):
            sub = None
    return problems


def test_every_module_architecture_md_names_exists():
    problems = architecture_problems(ARCHITECTURE.read_text(encoding="utf-8"))
    assert not problems, "docs/architecture.md names what the source lacks:\n" + "\n".join(problems)


def test_a_module_that_does_not_exist_is_found():
    text = ARCHITECTURE.read_text(encoding="utf-8")
    bogus = text.replace("## The store: two sides", "`benchmark.camera.nowhere`, `benchmark/camera/nowhere.py`, "
                         "`optics.no_such_function`, `benchmark.camera.optics.OpticalImage.no_such_member`\n\n"
                         "## The store: two sides", 1)
    bogus = bogus.replace("    calibration  ", "    calibration, nowhere  ", 1)
    problems = architecture_problems(bogus)
    assert len(problems) == 5, problems
    assert architecture_problems(text) == []


# --- headings the docs point at ----------------------------------------------------------------------------


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _page_text(page: Path) -> str:
    return re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)


@functools.cache
def _headings(page: Path) -> tuple[str, ...]:
    return tuple(m.group(1).strip() for m in re.finditer(r"^#{1,6} (.+)$", _page_text(page), flags=re.M))


@functools.cache
def _sections(page: Path) -> tuple[str, ...]:
    """The headings, and the bold words that open a paragraph or an item (``**Store size.**``):
    what a quoted section name may point at."""
    leads = re.findall(r"^(?:[-*] )?\*\*([^*\n]+?)\.?\*\*", _page_text(page), flags=re.M)
    return _headings(page) + tuple(leads)


def _names_a_section(page: Path, name: str) -> bool:
    """A quoted section name: a heading or a paragraph's bold lead of ``page`` begins with it
    (markup aside)."""
    plain = name.replace("`", "")
    return any(h.startswith(name) or h.replace("`", "").startswith(plain) for h in _sections(page))


LINK = re.compile(r"\]\(([^)\s#]+\.md)#([^)\s]+)\)")
QUOTED = re.compile(r"\b((?:docs/)?[\w-]+\.md)(?:,| \(|, section) (?:\"([^\"\n]+)\"|'([^'\n]+)')")
SOURCES = ("README.md", "CHANGELOG.md", "docs", "manifests", "metricscenes", "benchmark", "benchmarks", "tests",
           "leaderboard/README.md", "examples")


def _sources():
    for name in SOURCES:
        path = REPO / name
        files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.suffix in {".md", ".py", ".sh", ".yaml", ".ipynb"})
        yield from (f for f in files if f.name != Path(__file__).name)


def heading_problems() -> list[str]:
    problems = []
    for source in _sources():
        text = source.read_text(encoding="utf-8")
        where = source.relative_to(REPO)
        for target, anchor in LINK.findall(text):
            page = (source.parent / target).resolve()
            if not page.is_file():
                problems.append(f"{where}: {target}: no such page")
            elif anchor not in {_slug(h) for h in _headings(page)}:
                problems.append(f"{where}: {target}#{anchor}: no such heading")
        for target, double, single in QUOTED.findall(text):
            page, name = DOCS / Path(target).name, double or single
            if page.is_file() and not _names_a_section(page, name):
                problems.append(f'{where}: {target}, "{name}": no such heading')
    return problems


def test_links_and_section_names_find_their_headings():
    problems = heading_problems()
    assert not problems, "\n".join(problems)
