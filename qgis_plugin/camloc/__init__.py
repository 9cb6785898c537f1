"""camloc QGIS plugin: find where a street camera stands, with camloc_geo.

The plugin is thin: every computation runs in camloc_geo, in a separate Python process
(see ``runner``), so QGIS never loads the shapely/pyproj wheels next to its own GEOS/PROJ.
"""


def classFactory(iface):
    """QGIS entry point (``iface`` is None under qgis_process)."""
    from .plugin import CamlocPlugin

    return CamlocPlugin(iface)
