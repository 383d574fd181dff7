"""The stages of jacgen import one way (inputs, model, solvers, reports, emission, checking),
and no module of jacgen/ reaches, directly or through others, back to itself. Lazy imports
inside functions count too (stricter than module-level imports alone). No module is longer
than one idea needs (LONGEST_MODULE)."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "jacgen"


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, modules: set[str]) -> set[str]:
    """The jacgen modules `path` imports (relative or absolute, anywhere in the file)."""
    package = module_name(path) if path.name == "__init__.py" else module_name(path).rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                stem = ".".join(base + ([node.module] if node.module else []))
            else:
                stem = node.module or ""
            # `from . import ik` imports the module jacgen.ik; `from . import __version__`, the package
            candidates = [f"{stem}.{alias.name}" if f"{stem}.{alias.name}" in modules else stem for alias in node.names]
        elif isinstance(node, ast.Import):
            candidates = [alias.name for alias in node.names]
        else:
            continue
        found |= {name for name in candidates if name in modules}
    return found


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module, or a module importing itself."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        on_stack.add(module)
        for target in sorted(graph[module]):
            if target not in index:
                visit(target)
                low[module] = min(low[module], low[target])
            elif target in on_stack:
                low[module] = min(low[module], index[target])
        if low[module] == index[module]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == module:
                    break
            if len(component) > 1 or module in graph[module]:
                found.append(sorted(component))

    for module in sorted(graph):
        if module not in index:
            visit(module)
    return found


def test_no_import_circle_in_jacgen():
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(path) for path in paths}
    graph = {module_name(path): imports(path, modules) - {module_name(path)} for path in paths}
    assert sum(len(targets) for targets in graph.values()) > 50  # the parse found the imports
    assert cycles(graph) == []


# The stage folders of jacgen/ in the order the data flows; a stage imports only earlier ones.
# The modules at the top of jacgen/ are the command line and what its commands share.
STAGES = ("inputs", "model", "solvers", "reports", "emission", "checking")


def stage(module: str) -> int | None:
    parts = module.split(".")
    return STAGES.index(parts[1]) if len(parts) > 2 and parts[1] in STAGES else None


def test_the_stages_import_one_way():
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(path) for path in paths}
    backwards = sorted((module_name(path), target) for path in paths for target in imports(path, modules)
                       if stage(module_name(path)) is not None and stage(target) is not None
                       and stage(target) > stage(module_name(path)))
    assert backwards == []


def test_a_circle_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


# The modules that check generated code or an imported file against the oracle; nothing that
# generates may read it (its numbers come from `numeric_chain`, a separate implementation).
CHECKERS = {"jacgen.checking.verify", "jacgen.checking.dexterity_checks", "jacgen.checking.generated_code",
            "jacgen.checking.cortex_m4f", "jacgen.urdf_import"}


def test_only_the_checkers_import_the_reference():
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(path) for path in paths}
    readers = {module_name(path) for path in paths if "jacgen.checking.reference" in imports(path, modules)}
    assert readers and readers <= CHECKERS, readers - CHECKERS


def test_every_package_is_installed():
    """`pip install .` (not editable) installs the packages pyproject.toml lists: each folder of
    jacgen/ with an __init__.py must be among them, or the installed jacgen cannot import it."""
    import tomllib

    listed = set(tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {module_name(path.parent / "__init__.py") for path in PACKAGE.rglob("__init__.py")}
    assert found <= listed, found - listed


LONGEST_MODULE = 450  # lines: a module longer than this holds more than one idea


def test_no_module_is_longer_than_one_idea():
    long = {module_name(path): n for path in sorted(PACKAGE.rglob("*.py"))
            if (n := len(path.read_text().splitlines())) > LONGEST_MODULE}
    assert long == {}
