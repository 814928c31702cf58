"""Exceptions of the fesd package."""


class FesdError(RuntimeError):
    """A libfesd call failed. status: the library's code; status_name and status_text its name
    and message (fesd_status_name / fesd_status_string); detail: what the wrapper adds (the
    failed callback, the time)."""

    def __init__(self, status, status_name, status_text, detail=""):
        self.status, self.status_name, self.status_text, self.detail = status, status_name, status_text, detail
        msg = f"{status_name}: {status_text}"
        super().__init__(msg + (f" ({detail})" if detail else ""))


class CallbackError(FesdError):
    """A Python model callback failed (it raised, returned the wrong shape or a non-finite value)
    and the library stopped with FESD_ERR_CALLBACK / FESD_ERR_NONFINITE (or gave up on the step
    after that). callback: the Python callable's role ("fields", "switch", "drift", "events",
    ...), sys/mode where they apply, t: the time of the evaluation. The original exception is
    __cause__."""

    def __init__(self, status, status_name, status_text, detail, callback=None, sys=None, mode=None, t=None):
        super().__init__(status, status_name, status_text, detail)
        self.callback, self.sys, self.mode, self.t = callback, sys, mode, t


class OutputShapeError(ValueError):
    """A callback returned an array of the wrong shape."""


class NonFiniteOutputError(FloatingPointError):
    """A callback returned NaN or Inf."""
