"""A library of the camera extra that cannot be imported is reported with its real cause: not installed (the
install command), or installed but unable to load (the missing system library and the package providing it)."""

import importlib
from types import SimpleNamespace

import pytest

from graspexp.config.perception import CAMERA_EXTRA
from graspexp.perception import registration
from graspexp.perception.imports import import_optional


def _failing(monkeypatch, module: str, exc: ImportError) -> None:
    """Importing ``module`` through :mod:`graspexp.perception.imports` raises ``exc`` (nothing else changes)."""
    real = importlib.import_module

    def fake(name: str, *args):
        if name == module:
            raise exc
        return real(name, *args)

    registration.open3d.cache_clear()  # it keeps the module once loaded
    # the modules the functions were defined in (another test may have re-imported the package)
    for fn in (import_optional, registration.import_optional):
        monkeypatch.setitem(fn.__globals__, "importlib", SimpleNamespace(import_module=fake))


def test_an_installed_library_that_cannot_load_names_the_missing_system_library(monkeypatch):
    """Open3D's CPU wheel on a machine without libusb (the loader's own message, as Python raises it)."""
    _failing(
        monkeypatch,
        "open3d",
        ImportError("libusb-1.0.so.0: cannot open shared object file: No such file or directory"),
    )
    with pytest.raises(ImportError) as err:
        registration.open3d()
    message = str(err.value)
    assert message == (
        "pose registration needs open3d-cpu, installed but it cannot load: the system library libusb-1.0.so.0 is "
        "missing: install the system package libusb-1.0-0 (Debian/Ubuntu: apt-get install libusb-1.0-0)"
    )
    assert "not installed" not in message


def test_an_unknown_missing_library_or_another_load_error_keeps_the_loaders_words(monkeypatch):
    _failing(
        monkeypatch, "embreex", ImportError("libembree4.so.4: cannot open shared object file: No such file")
    )
    with pytest.raises(
        ImportError,
        match="the system library libembree4.so.4 is missing: install the system package that provides it$",
    ):
        import_optional("embreex", "embreex", "the depth camera")
    _failing(monkeypatch, "embreex", ImportError("undefined symbol: rtcNewDevice"))
    with pytest.raises(ImportError, match="installed but it cannot load: undefined symbol: rtcNewDevice$"):
        import_optional("embreex", "embreex", "the depth camera")


def test_a_library_that_is_not_installed_gives_the_install_command(monkeypatch):
    _failing(monkeypatch, "open3d", ModuleNotFoundError("No module named 'open3d'", name="open3d"))
    with pytest.raises(ImportError) as err:
        import_optional("open3d", "open3d-cpu", "pose registration")
    assert str(err.value) == f"pose registration needs open3d-cpu, not installed: {CAMERA_EXTRA}"
