"""The perception stage's optional libraries (the camera extra: embreex, Open3D), imported when first used,
with the real cause when one cannot be: not installed, or installed but unable to load (a system library
it links against is missing)."""

import importlib
import re
from types import ModuleType

from graspexp.config.perception import CAMERA_EXTRA

SYSTEM_LIBRARIES = {"libusb-1.0.so.0": "libusb-1.0-0"}
"""Shared libraries the camera extra's wheels load from the system -> the Debian/Ubuntu package that provides
each (Open3D's CPU wheel links libusb-1.0)."""
_MISSING_LIBRARY = re.compile(r"(lib[\w.+-]+\.so[\w.]*): cannot open shared object file")


def import_optional(module: str, package: str, needed_by: str) -> ModuleType:
    """``module`` imported; ImportError in one line otherwise: ``package`` is not installed (with the install
    command), or it is installed and cannot load (the missing shared library and the system package that
    provides it, or the loader's own message). ``needed_by`` says what needs it (e.g. "pose registration")."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and exc.name.split(".")[0] == module.split(".")[0]:
            raise ImportError(f"{needed_by} needs {package}, not installed: {CAMERA_EXTRA}") from None
        raise ImportError(f"{needed_by} needs {package}, installed but it cannot load: {exc}") from None
    except ImportError as exc:
        raise ImportError(
            f"{needed_by} needs {package}, installed but it cannot load: {_cause(str(exc))}"
        ) from None


def _cause(message: str) -> str:
    """The loader's message, with the system package to install when it names a missing shared library."""
    found = _MISSING_LIBRARY.search(message)
    if found is None:
        return message
    library = found.group(1)
    provider = SYSTEM_LIBRARIES.get(library)
    how = (
        f"install the system package {provider} (Debian/Ubuntu: apt-get install {provider})"
        if provider
        else ("install the system package that provides it")
    )
    return f"the system library {library} is missing: {how}"
