"""Session 39 QA: a job's summary page (``GET /v1/jobs/{id}/map``) said "1 camera(s)
located" over a camera placed only at the junction its title names (status
``title_only``): the job's title candidates carried no status in their ``flags``, which the
page's heading reads. ``camloc batch --map``'s page of the same list says "1 camera(s) on
the map: 1 title_only (at the junction its title names)".
"""

from __future__ import annotations

import re
from typing import Any

from camloc_geo.service.routers.jobs import job_summary_page


def _title_only_result() -> dict[str, Any]:
    lat, lon = 39.28557975, -76.59348405
    return {
        "id": "1",
        "title": "Eastern Avenue & South Broadway",
        "status": "title_only",
        "reason": "junction of the map's model, at the nodes the two streets share",
        "lat": lat,
        "lon": lon,
        "score": 1.0,
        "uncertainty_m": 21.5,
        "method": "title",
        "candidates": [
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [lon, lat]},
                "properties": {
                    "kind": "candidate",
                    "rank": 1,
                    "source": "title",
                    "status": "junction",
                    "score": 1.0,
                    "lat": lat,
                    "lon": lon,
                    "uncertainty_m": 21.5,
                    "method": "title:junction",
                    "camera_id": "1",
                },
            }
        ],
    }


def _heading(page: str) -> str:
    text = page.replace("\\u003c", "<").replace("\\u003e", ">")
    found = re.search(r"<h4>([^<]*camera\(s\)[^<]*)</h4>([^<]*)", text)
    assert found is not None
    return found.group(1) + " | " + found.group(2)


def test_a_title_only_camera_is_not_called_located() -> None:
    heading = _heading(job_summary_page([_title_only_result()]))
    assert heading == "1 camera(s) on the map | 1 title_only (at the junction its title names)"


def test_a_street_only_and_a_located_camera_are_counted_apart() -> None:
    street = _title_only_result()
    street["status"] = "street_only"
    located = _title_only_result()
    located.update(id="2", status="located", method="locate")
    located["candidates"][0]["properties"]["flags"] = ["far_from_prior"]
    heading = _heading(job_summary_page([street, located]))
    assert heading == (
        "2 camera(s) on the map | 1 located, 1 street_only (on the street its title names)"
    )
