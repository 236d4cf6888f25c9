"""``interplay run SCENE --controller FILE``: run the controller a search found.

FILE is the ``tune.json`` that ``interplay tune SCENE`` writes (its ``best``: {dotted key:
value}) or a JSON object of those keys alone. Its keys must be exactly the search's
parameters: a file of another scene, an unknown key or a missing one is one line, before
anything is simulated.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import ParameterError


def controller_sets(spec, path) -> dict:
    """``--set`` assignments {dotted key: text} for the controller in ``path``."""
    if not spec.searches:
        raise ParameterError(f"--controller {path}: {spec.name} has no controller search")
    try:
        doc = json.loads(Path(path).read_text())
    except OSError as e:
        raise ParameterError(f"--controller {path}: cannot read it ({e.strerror})") from None
    except json.JSONDecodeError as e:
        raise ParameterError(f"--controller {path}: not JSON ({e.msg}, line {e.lineno})") \
            from None
    if not isinstance(doc, dict):
        raise ParameterError(f"--controller {path}: expected a JSON object of parameters")
    if "scene" in doc and doc["scene"] != spec.name:
        raise ParameterError(f"--controller {path}: a controller for {doc['scene']}, not "
                             f"{spec.name}")
    search = spec.search(doc.get("search"))
    values = doc.get("best", doc) if "scene" in doc else doc
    if not isinstance(values, dict):
        raise ParameterError(f"--controller {path}: its best is not an object of parameters")
    names = list(search.bounds)
    unknown = sorted(set(values) - set(names))
    missing = [n for n in names if n not in values]
    if unknown or missing:
        what = "; ".join(s for s in (
            f"unknown {', '.join(unknown)}" if unknown else "",
            f"missing {', '.join(missing)}" if missing else "") if s)
        raise ParameterError(f"--controller {path}: {what}; the {spec.name} {search.name} "
                             f"search's parameters are {', '.join(names)}")
    bad = [k for k, v in values.items()
           if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)]
    if bad:
        raise ParameterError(f"--controller {path}: {', '.join(bad)} must be finite numbers")
    return {k: repr(float(v)) for k, v in values.items()}
