"""``vo_doppler.model`` exports its dataclasses as the README says, without loading them all."""

from __future__ import annotations

import importlib
import re
import subprocess
import sys

import pytest

import vo_doppler.model as model
from tests.conftest import REPO_ROOT


def readme_model_names() -> list[str]:
    """The class names the README lists after "the plain dataclasses of `vo_doppler.model`"."""
    text = " ".join((REPO_ROOT / "README.md").read_text().split())
    claim = re.search(r"dataclasses of `vo_doppler\.model` over numpy arrays \(a (.*?)\)", text)
    assert claim, "the README no longer states what vo_doppler.model holds"
    return re.findall(r"`(\w+)`", claim.group(1))


def test_the_readme_names_import_from_vo_doppler_model():
    names = readme_model_names()
    assert {"Sequence", "SensorSeries", "Trajectory", "HeadingTable"} <= set(names)
    namespace: dict = {}
    exec(f"from vo_doppler.model import {', '.join(names)}", namespace)
    assert all(namespace[name].__name__ == name for name in names)


@pytest.mark.parametrize("name", model.__all__)
def test_every_export_is_the_class_its_module_defines(name):
    module = importlib.import_module(f"vo_doppler.model.{model.EXPORTS[name]}")
    assert getattr(model, name) is getattr(module, name)


def test_all_lists_the_exports_and_unknown_names_fail():
    assert model.__all__ == sorted(model.EXPORTS)
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        _ = model.Nope


def test_importing_one_model_module_loads_neither_the_others_nor_scipy():
    code = (
        "import sys, vo_doppler.model.series\n"
        "print('scipy' in sys.modules, 'vo_doppler.model.trajectory' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["False", "False"]
