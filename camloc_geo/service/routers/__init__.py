"""The service's routes, one router per area: scenes, maps, jobs, crowd, verdicts, and meta
(health, docs)."""

from camloc_geo.service.routers import crowd, jobs, maps, meta, scenes, verdicts

ROUTERS = (meta.router, scenes.router, maps.router, jobs.router, crowd.router, verdicts.router)
"""Every router, in the order the OpenAPI description lists them."""

__all__ = ["ROUTERS"]
