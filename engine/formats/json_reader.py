"""Reading values out of parsed JSON (scene files, glTF documents): each malformed value raises
SceneError naming the file and the field, e.g. `scenes/x.json: objects[6] "Short Box".size: must
be positive`."""
import math
from pathlib import Path

import numpy as np

from ..core.errors import SceneError
from ..core.limits import MAX_MAGNITUDE


class JsonReader:
    """Typed, range-checked reads from parsed JSON; `path` names the file in errors."""

    def __init__(self, path):
        self.path = Path(path)

    def fail(self, field, message):
        raise SceneError(message, source=self.path, field=field)

    def get(self, obj, key, field, default=..., kind=None):
        if key not in obj:
            if default is ...:
                self.fail(f"{field}.{key}" if field else key, "missing")
            return default
        value = obj[key]
        if kind is int:  # JSON has one number type: 1.0 is the integer 1
            value = _integer(value)
        if kind is not None and not isinstance(value, kind):
            self.fail(f"{field}.{key}" if field else key, f"must be {_kind_name(kind)}")
        return value

    def number(self, obj, key, field, default=..., positive=False, minimum=None, maximum=MAX_MAGNITUDE, whole=False):
        value = self.get(obj, key, field, default)
        where = f"{field}.{key}" if field else key
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, "must be a number")
        if not _finite(value):
            self.fail(where, "must be finite")
        if whole and value != int(value):
            self.fail(where, "must be a whole number")
        if positive and value <= 0:
            self.fail(where, "must be positive")
        if minimum is not None and value < minimum:
            self.fail(where, f"must be at least {minimum:g}")
        if value > maximum:
            self.fail(where, f"must be at most {maximum:g}")
        if value < -MAX_MAGNITUDE:
            self.fail(where, f"must be at least {-MAX_MAGNITUDE:g}")
        return float(value)

    def vector(self, obj, key, field, default=..., length=3, positive=False, nonnegative=False, maximum=MAX_MAGNITUDE):
        value = self.get(obj, key, field, default)
        if value is default and default is not ...:
            return np.array(default, float)
        return self.vector_value(value, f"{field}.{key}" if field else key, length, positive, nonnegative, maximum)

    def vector_value(self, value, where, length=3, positive=False, nonnegative=False, maximum=MAX_MAGNITUDE):
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f"must be a list of {length} numbers")
        for i, v in enumerate(value):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or v is None:
                self.fail(f"{where}[{i}]", "must be a number")
            if not _finite(v):
                self.fail(f"{where}[{i}]", "must be finite (got NaN, infinity or an out-of-range number)")
            if positive and v <= 0:
                self.fail(f"{where}[{i}]", "must be positive")
            if nonnegative and v < 0:
                self.fail(f"{where}[{i}]", "must not be negative")
            if v > maximum:
                self.fail(f"{where}[{i}]", f"must be at most {maximum:g}")
            if v < -MAX_MAGNITUDE:
                self.fail(f"{where}[{i}]", f"must be at least {-MAX_MAGNITUDE:g}")
        return np.array(value, float)

    def index(self, obj, key, field, array, count, default=...):
        """A whole number naming an element of the list `array` (`count` long), e.g. a glTF
        accessor index."""
        value = self.get(obj, key, field, default)
        if value is default and default is not ...:
            return value
        return self.index_value(value, f"{field}.{key}" if field else key, array, count)

    def index_value(self, value, where, array, count):
        value = _integer(value)
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < count:
            self.fail(where, f"must be the index of one of the file's {count} {array}, got {value!r}")
        return value


def _integer(value):
    """A JSON number with no fraction as a Python int (1.0 -> 1); anything else as it is."""
    if isinstance(value, float) and _finite(value) and value == int(value):
        return int(value)
    return value


def _kind_name(kind):
    names = {dict: "an object", list: "a list", str: "a string", bool: "true or false"}
    return names.get(kind, kind.__name__ if isinstance(kind, type) else "valid")


def _finite(value):
    try:
        return math.isfinite(value)
    except OverflowError:  # an integer too large for a float
        return False
