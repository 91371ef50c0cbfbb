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
