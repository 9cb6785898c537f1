"""The QGIS plugin's front end in the library: its out-of-process worker (:mod:`.worker`).

Nothing here imports qgis or Qt: the plugin (``qgis_plugin/camloc``) runs
``python -m camloc_geo.qgis.worker JOB.json`` in a Python that has ``camloc_geo``.
"""
