"""Lazy access to MuJoCo, the optional extra ``feederkit[sim]``."""

from __future__ import annotations

from types import ModuleType

from feederkit.errors import InputError

MISSING_MESSAGE = (
    "the simulator needs MuJoCo: install feederkit[sim] (in a clone: "
    "pip install -c requirements.lock -e '.[sim]')"
)


def mujoco_available() -> bool:
    """Whether ``import mujoco`` works here."""
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


def require_mujoco() -> ModuleType:
    """The ``mujoco`` module, or InputError with one line telling how to install it."""
    try:
        import mujoco
    except ImportError:
        raise InputError(MISSING_MESSAGE) from None
    return mujoco
