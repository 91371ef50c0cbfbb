from traj2events.settings.site import terrain_files


def test_the_render_rule_reads_every_file_of_the_products(tmp_path):
    # A PDS3 product is a label and an image: editing either reruns the render.
    (tmp_path / "SITE.LBL").write_text("PDS_VERSION_ID = PDS3\n")
    (tmp_path / "SITE.IMG").write_bytes(b"\0" * 8)
    far = tmp_path / "far.tif"
    dem = {"file": str(tmp_path / "SITE.LBL"), "site": {"lat_deg": -89.5, "lon_deg": 0.0}, "far": str(far)}
    assert terrain_files({"dem": dem}) == [str(tmp_path / "SITE.LBL"), str(tmp_path / "SITE.IMG"), str(far)]
    assert terrain_files({"dem": {**dem, "far": None}}) == [str(tmp_path / "SITE.LBL"), str(tmp_path / "SITE.IMG")]
    assert terrain_files({"elevation_grid": "grid.npy", "dem": None}) == ["grid.npy"]
    assert terrain_files({"dem": None}) == []


def test_a_date_between_two_is_the_fraction_of_the_way_to_the_second():
    from traj2events.settings.site import date_between

    assert date_between("2027-03-01T00:00:00", "2027-03-03T00:00:00", 0.25) == "2027-03-01T12:00:00"
    assert date_between("2027-03-01T00:00:00", "2027-03-01T00:00:10", 1 / 3) == "2027-03-01T00:00:03"  # to the second
    assert date_between("2027-12-31T23:00:00", "2028-01-01T01:00:00", 0.5) == "2028-01-01T00:00:00"
