"""Compiled kernels (numba) whose on-disk cache survives any import name and any stale entry.

numba's own cache sits beside the sources (``__pycache__/*.nbi``) and its entries name the
module they were compiled in: once the plugin folder was imported under another package name
(``pytest --doctest-modules`` names it after the checkout's folder, a GitHub zip unpacks as
``lidarphoto-main``), loading them as ``lidarphoto`` fails (``No module named 'main'``).
:func:`cached_njit` compiles as ``numba.njit(cache=True)`` does, but keeps the cache in the
user's cache folder (:func:`cache_folder`), one folder per import name, package version and
source folder, and compiles afresh when an entry cannot be loaded, whatever the reason (numba
then writes the entry anew).

numba is optional: :data:`AVAILABLE` tells whether it imports.
"""

from __future__ import annotations

import hashlib
import logging
import os
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Callable

try:  # pragma: no cover - depends on the environment
    import numba

    AVAILABLE = True
except Exception:  # ImportError, or a numba built against another numpy
    numba = None
    AVAILABLE = False

log = logging.getLogger(__name__)

__all__ = ["AVAILABLE", "Kernels", "cache_folder", "cached_njit", "compiled_kernel"]

#: The package folder (the plugin's root, whatever it is named) and its import name.
_ROOT = Path(__file__).resolve().parents[1]
_PACKAGE = __name__.split(".")[0]


def user_cache_root() -> Path:
    """The user's cache folder: ``NUMBA_CACHE_DIR`` when set, else ``%LOCALAPPDATA%``
    (Windows), ``~/Library/Caches`` (macOS) or ``$XDG_CACHE_HOME`` / ``~/.cache``."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        return Path(given)
    if os.name == "nt":
        return Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")


def cache_folder() -> Path:
    """Where the kernels of this copy of the package are cached:
    ``<user cache>/lidarphoto/numba/<import name>-<version>-<hash of the package folder>``
    (two checkouts or worktrees never share entries, nor two import names of one folder)."""
    from . import __version__

    digest = hashlib.sha1(str(_ROOT).encode("utf-8", "replace")).hexdigest()[:10]
    return user_cache_root() / "lidarphoto" / "numba" / f"{_PACKAGE}-{__version__}-{digest}"


def _cache_class() -> type | None:
    """numba's function cache with our locator and a load that never fails; None when this
    numba lacks the parts used (the kernels are then compiled in every process)."""
    try:
        from numba.core.caching import (
            CompileResultCacheImpl,
            FunctionCache,
            _CacheLocator,
            _SourceFileBackedLocatorMixin,
        )
    except ImportError:
        return None

    class Locator(_SourceFileBackedLocatorMixin, _CacheLocator):
        """Entries of a module ``<pkg>.core.x.y`` in ``cache_folder()/core.x.y``."""

        def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            module = py_func.__module__.split(".", 1)[-1]
            self._cache_path = str(cache_folder() / module)

        def get_cache_path(self) -> str:
            return self._cache_path

    class Impl(CompileResultCacheImpl):
        _locator_classes = (Locator,)

    class Cache(FunctionCache):
        _impl_class = Impl

        def load_overload(self, sig: Any, target_context: Any) -> Any:
            try:
                return super().load_overload(sig, target_context)
            except Exception as exc:  # a stale or broken entry: compiled again, saved anew
                log.debug("compiled cache entry of %s not loaded (%s): compiling", self, exc)
                return None

    return Cache


_CACHE: list[type | None] = []


def cached_njit(func: Callable[..., Any], **options: Any) -> Callable[..., Any]:
    """``numba.njit(cache=True, **options)(func)`` with the cache of :func:`cache_folder`.

    The cache is left out (compiled in every process, with a debug message) when its folder
    cannot be written or this numba lacks the parts used.
    """
    dispatcher = numba.njit(**options)(func)
    if not _CACHE:
        _CACHE.append(_cache_class())
    cache = _CACHE[0]
    if cache is not None:
        try:
            dispatcher._cache = cache(func)
        except Exception as exc:  # no writable cache folder, another numba's internals
            log.debug("no compiled cache for %s: %s", func.__qualname__, exc)
    return dispatcher


_KERNELS: dict[Callable[..., Any], Callable[..., Any]] = {}


def compiled_kernel(
    func: Callable[..., Any], helpers: tuple[Callable[..., Any], ...] = ()
) -> Callable[..., Any] | None:
    """``func`` compiled once per process (:func:`cached_njit`, ``nogil``), or None without
    numba: for modules that stay light until a kernel is first asked for (they import this
    function inside theirs).

    ``helpers``: plain functions of ``func``'s module that it calls by name (one routine
    that several kernels share instead of each writing it out); each is compiled once (the
    same way) and put in place of its name in the module's globals before ``func`` is
    compiled, so that the kernel calls compiled code.
    """
    if not AVAILABLE:
        return None
    if func not in _KERNELS:
        space = func.__globals__
        for helper in helpers:
            plain = getattr(helper, "py_func", helper)  # named again once put in place
            if plain not in _KERNELS:
                _KERNELS[plain] = cached_njit(plain, nogil=True)
            space[plain.__name__] = _KERNELS[plain]
        _KERNELS[func] = cached_njit(func, nogil=True)
    return _KERNELS[func]


class Kernels:
    """One module's numba kernels by name, each compiled (:func:`cached_njit`, ``nogil`` and
    ``options``) at its first use and kept: ``_compiled = Kernels({"cells": _cells_kernel})``,
    then ``_compiled("cells")(...)``. Nothing is compiled (nor numba needed) until then."""

    def __init__(self, kernels: Mapping[str, Callable[..., Any]], **options: Any) -> None:
        self._kernels = dict(kernels)
        self._options = {"nogil": True, **options}
        self._done: dict[str, Callable[..., Any]] = {}

    def __call__(self, name: str) -> Callable[..., Any]:
        """The compiled kernel ``name``."""
        if name not in self._done:
            self._done[name] = cached_njit(self._kernels[name], **self._options)
        return self._done[name]
