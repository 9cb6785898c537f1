"""Session 37 QA: the HTTP service's job lists read as ``camloc batch`` reads them."""

from __future__ import annotations

from camloc_geo.service.routers.jobs import camera_records, csv_encoding_warning


def test_job_csv_in_windows_1252_is_read() -> None:
    """A spreadsheet's Windows-1252 export was refused (422 "the CSV list is not UTF-8
    text") although ``POST /v1/jobs`` reads lists "with camloc batch's reader", which reads
    it as Windows-1252 with a warning. It is read so, and the answer's warning says how."""
    body = "id;title;lat;lon\nk1;Straße & Blücherplatz;52,5;13,4\n".encode("cp1252")
    (cam,) = camera_records(body, "text/csv", 10)
    assert cam["id"] == "k1"
    assert cam["title"] == "Straße & Blücherplatz"
    assert (cam["lat"], cam["lon"]) == (52.5, 13.4)
    warning = csv_encoding_warning(body)
    assert warning is not None
    assert "read as Windows-1252" in warning
    utf8 = "\ufeffid,title\nk1,Straße & Blücherplatz\n".encode()
    assert camera_records(utf8, "text/csv", 10)[0]["title"] == "Straße & Blücherplatz"
    assert csv_encoding_warning(utf8) is None
