"""Reference objects: the known-size things annotators mark (cars, mostly).

Dimensions are the bounding box of the body, metres: ``length`` along the direction of
travel, ``width`` without mirrors, ``height`` from the ground to the roof. They are rounded
medians of common models in each class (2015-2024 European and North American
registrations); a real car differs from its preset by up to about 10 %, which the
benchmarks model.

==========  ========  =======  ========  =======================================
preset      length    width    height    typical models
==========  ========  =======  ========  =======================================
sedan       4.60      1.80     1.45      Toyota Camry/Corolla sedan, VW Passat
hatchback   4.20      1.78     1.47      VW Golf, Ford Focus, Toyota Yaris
suv         4.70      1.88     1.70      Toyota RAV4, Honda CR-V, VW Tiguan
pickup      5.60      2.03     1.90      Ford F-150, Toyota Hilux (5.3/1.86/1.82)
van         5.30      2.00     2.30      Ford Transit, Mercedes Sprinter (short)
minivan     5.10      1.98     1.75      Honda Odyssey, Toyota Sienna
taxi_ny     5.00      1.95     1.85      New York yellow cab (Toyota Sienna/Nissan NV200 mix)
bus         12.00     2.55     3.10      12 m city bus (EU max width 2.55 m)
==========  ========  =======  ========  =======================================

The default, when a scene says nothing, is ``sedan``: the paper used fixed sedan
dimensions and found that a neural size estimate did not help.
"""

from __future__ import annotations

from dataclasses import dataclass

from camloc_geo._errors import SceneError

__all__ = ["DEFAULT_PRESET", "PRESETS", "ObjectSize", "object_preset"]


@dataclass(frozen=True)
class ObjectSize:
    """Size of a box-shaped reference object, metres."""

    length_m: float
    width_m: float
    height_m: float

    def __post_init__(self) -> None:
        for name in ("length_m", "width_m", "height_m"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0 and value < 1e4):
                raise SceneError(
                    f"must be a positive size in metres, got {value!r}", f"object.{name}"
                )

    def dimension(self, axis: str) -> float:
        """The size along ``length``, ``width`` or ``height``."""
        return float(getattr(self, f"{axis}_m"))


PRESETS: dict[str, ObjectSize] = {
    "sedan": ObjectSize(4.60, 1.80, 1.45),
    "hatchback": ObjectSize(4.20, 1.78, 1.47),
    "suv": ObjectSize(4.70, 1.88, 1.70),
    "pickup": ObjectSize(5.60, 2.03, 1.90),
    "van": ObjectSize(5.30, 2.00, 2.30),
    "minivan": ObjectSize(5.10, 1.98, 1.75),
    "taxi_ny": ObjectSize(5.00, 1.95, 1.85),
    "bus": ObjectSize(12.00, 2.55, 3.10),
}
DEFAULT_PRESET = "sedan"


def object_preset(name: str) -> ObjectSize:
    """Look up a preset by name (case-insensitive); SceneError listing the known ones."""
    key = name.strip().lower().replace("-", "_").replace(" ", "_")
    if key not in PRESETS:
        raise SceneError(
            f"unknown object preset {name!r}; known: {', '.join(sorted(PRESETS))}", "object.preset"
        )
    return PRESETS[key]
