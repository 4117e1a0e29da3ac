"""The boundary between Python and the extension: every public function of
:mod:`sagcal` is wrapped by :func:`entry`, which

- checks the integer and list arguments first, so that a negative count, a
  seed outside ``[0, 2**64)`` or a string where a list is expected raises
  :class:`SagcalError` naming the argument (the extension's own conversion
  would raise ``OverflowError`` or "Can't extract `str` to `Vec`"); a
  conversion the extension refuses (``TypeError: argument 'x': ...``) is
  turned into a :class:`SagcalError` too;
- turns a Rust panic (pyo3's ``PanicException``, a ``BaseException`` that
  ``except Exception`` does not catch) into a :class:`SagcalError` naming the
  call, ``internal error in sagcal.NAME: ... please report``;
- runs the call in a worker thread and waits for it in the main thread, so
  that Ctrl-C (SIGINT) raises ``KeyboardInterrupt`` at once, however long the
  job (the extension releases the GIL while it works), and asks the library
  to stop the job (``sagcal::cancel``: its long loops check the flag).
"""

import functools
import re
import threading

from . import _sagcal
from ._sagcal import InvalidInputError, SagcalError

#: Largest seed + 1: seeds are unsigned 64-bit integers.
SEED_LIMIT = 2**64

#: How long Ctrl-C waits for the job to stop before raising KeyboardInterrupt, seconds.
STOP_WAIT_S = 2.0

#: How often the waiting main thread wakes up to let Python run its signal handlers, seconds.
POLL_S = 0.05


def _invalid(message):
    return InvalidInputError(f"invalid input: {message}")


def check_int(name, value, low=0, high=SEED_LIMIT):
    """``value`` as an int in ``[low, high)``, or a :class:`SagcalError` naming ``name``."""
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise _invalid(f"{name} must be a whole number, got {value!r} ({type(value).__name__})")
    value = value.__index__()
    if not low <= value < high:
        upper = "2**64" if high == SEED_LIMIT else str(high)
        raise _invalid(f"{name} must be a whole number in [{low}, {upper}), got {value}")
    return value


def check_strings(name, value):
    """``value`` as a list of strings (``None`` kept), or a :class:`SagcalError` naming ``name``."""
    if value is None:
        return None
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise _invalid(f"{name} must be a list of strings, got {value!r} ({type(value).__name__})")
    items = list(value)
    for item in items:
        if not isinstance(item, str):
            raise _invalid(f"{name} must be a list of strings, got an item {item!r} ({type(item).__name__})")
    return items


def conversion_argument(error):
    """The argument whose conversion by the extension raised ``error``
    (pyo3 notes ``while processing 'NAME'`` or says ``argument 'NAME': ...``), or ``None``."""
    for note in getattr(error, "__notes__", ()):
        found = re.match(r"while processing '([^']+)'", note)
        if found:
            return found.group(1)
    found = re.match(r"argument '([^']+)'", str(error))
    return found.group(1) if found else None


def is_panic(error):
    """Whether ``error`` is a Rust panic that crossed into Python (pyo3's ``PanicException``)."""
    return type(error).__name__ == "PanicException"


def internal_error(call, error):
    """The :class:`SagcalError` for a panic of ``sagcal.<call>``."""
    return SagcalError(f"internal error in sagcal.{call}: {error}; please report it with the input that caused it")


def run_interruptibly(function, args, kwargs):
    """``function(*args, **kwargs)`` in a worker thread, the main thread
    waiting so that Ctrl-C raises ``KeyboardInterrupt`` at once; from any
    other thread the call is made directly."""
    if threading.current_thread() is not threading.main_thread():
        return function(*args, **kwargs)
    outcome = {}
    done = threading.Event()

    def work():
        try:
            outcome["value"] = function(*args, **kwargs)
        except BaseException as error:  # handed to the caller's thread
            outcome["error"] = error
        finally:
            done.set()

    worker = threading.Thread(target=work, name=f"sagcal.{getattr(function, '__name__', 'call')}", daemon=True)
    _sagcal._reset_cancel()
    try:
        # Started inside the ``try``: ``Thread.start`` waits for the thread
        # to run, and a Ctrl-C in that wait must stop the job too.
        worker.start()
        while not done.wait(POLL_S):
            pass
    except KeyboardInterrupt:
        # The job stops at its next check (the library's cancellation flag).
        _sagcal._cancel()
        if done.wait(STOP_WAIT_S):
            worker.join(POLL_S)
        raise
    worker.join()
    if "error" in outcome:
        raise outcome.pop("error")
    return outcome["value"]


def entry(function, name=None, ints=None, lists=()):
    """``function`` wrapped as the module docstring says; ``ints`` maps an
    integer parameter to its ``(low, high)`` range, ``lists`` names the
    parameters that take a list of strings."""
    import inspect

    name = name or function.__name__
    signature = inspect.signature(function)
    ints = ints or {}

    @functools.wraps(function)
    def call(*args, **kwargs):
        try:
            bound = signature.bind(*args, **kwargs)
        except TypeError as error:
            raise _invalid(f"sagcal.{name}: {error}") from None
        for parameter, (low, high) in ints.items():
            if parameter in bound.arguments:
                bound.arguments[parameter] = check_int(parameter, bound.arguments[parameter], low, high)
        for parameter in lists:
            if parameter in bound.arguments:
                bound.arguments[parameter] = check_strings(parameter, bound.arguments[parameter])
        try:
            return run_interruptibly(function, bound.args, bound.kwargs)
        except (TypeError, OverflowError) as error:
            argument = conversion_argument(error)
            if argument is None:
                raise
            raise _invalid(f"sagcal.{name}: argument `{argument}`: {error}") from None
        except BaseException as error:
            if is_panic(error):
                raise internal_error(name, error) from None
            raise

    return call
