"""Pieces shared by the Integrator and the OCP (the lifetime of a library workspace) and by
their result dicts (solve_ivp's OdeResult, OCP.solve's OcpResult)."""
import ctypes

from . import _lib


class Handle:
    """Lifetime of one library workspace: the subclass keeps its pointer (a ctypes.c_void_p) in
    the attribute named by _HANDLE, freed by the library function _FREE; _WHAT names it in the
    error of a use after close()."""

    _HANDLE, _FREE, _WHAT = None, None, None

    def close(self):
        h = getattr(self, self._HANDLE, None)
        if h:
            getattr(_lib.lib, self._FREE)(ctypes.byref(h))

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _ptr(self):
        h = getattr(self, self._HANDLE, None)
        if not h:
            raise ValueError(f"the {self._WHAT} is closed")
        return h


class AttrDict(dict):
    """A dict with attribute access; repr shows the keys in _REPR_KEYS."""

    _REPR_KEYS = ()

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError as e:
            raise AttributeError(name) from e

    __setattr__ = dict.__setitem__

    def __repr__(self):
        return type(self).__name__ + "(\n" + "\n".join(f"  {k}: {self.get(k)!r}" for k in self._REPR_KEYS) + "\n)"
