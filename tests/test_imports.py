"""One-way imports: every module imports, the package layers hold, and docs/architecture.md states them.

The layers and the no-circle rule are import-linter contracts in ``pyproject.toml``
(``lint-imports`` runs them too); this file runs them and checks that docs/architecture.md's
architecture section lists the same layers in the same order.
"""

from __future__ import annotations

import importlib
import pkgutil
import re
import tomllib
from pathlib import Path

import pytest

import agentchord

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"
ARCHITECTURE = ROOT / "docs" / "architecture.md"


def _modules() -> list[str]:
    return sorted(m.name for m in pkgutil.walk_packages(agentchord.__path__, "agentchord."))


def _contract(contract_id: str) -> dict:
    config = tomllib.loads(PYPROJECT.read_text())["tool"]["importlinter"]
    return next(c for c in config["contracts"] if c["id"] == contract_id)


def _contract_layers() -> list[list[str]]:
    """The layers contract, top to bottom; each layer its packages in order."""
    return [[p.strip() for p in re.split(r"[|:]", layer)] for layer in _contract("layers")["layers"]]


def _readme_layers() -> list[list[str]]:
    """The architecture section's package lines, top to bottom; ``| pkg`` lines join the layer above."""
    text = ARCHITECTURE.read_text()
    section = text[text.index("# Architecture") :]
    start = section.index("```\nsrc/agentchord/") + 4
    block = section[start : section.index("\n```", start)]
    layers: list[list[str]] = []
    for line in block.splitlines()[1:]:
        match = re.match(r"^ {2,3}(\| )?((?:[a-z_]+/)*[a-z_]+(?:/|\.py))(?:\s|$)", line)
        if not match:
            continue
        module = "agentchord." + match.group(2).removesuffix(".py").strip("/").replace("/", ".")
        if match.group(1):
            layers[-1].append(module)
        else:
            layers.append([module])
    return layers


@pytest.mark.parametrize("name", _modules())
def test_every_module_imports(name: str) -> None:
    importlib.import_module(name)


def test_import_contracts_hold(tmp_path: Path) -> None:
    from importlinter.cli import lint_imports

    assert lint_imports(config_filename=str(PYPROJECT), no_cache=True, no_logo=True) == 0, (
        "an import contract of pyproject.toml is broken: run `lint-imports` for the offending imports"
    )


def test_readme_architecture_lists_the_layers_in_order() -> None:
    assert _readme_layers() == _contract_layers()


def test_every_top_level_module_is_in_a_layer() -> None:
    layered = {m for layer in _contract_layers() for m in layer}
    top = {f"agentchord.{m.name}" for m in pkgutil.iter_modules(agentchord.__path__)}
    # worlds/ is split across layers (its simulator, worlds.sim, above its protocol), and so is cli/
    # (its group, cli.app, above the commands above their support, cli.support).
    covered = {".".join(m.split(".")[:2]) for m in layered}
    assert top <= covered, f"modules in no layer: {sorted(top - covered)}"
