"""``catalog analyze`` advises a finer sensor only where one can help (Lemma 8)."""

from feederkit.cli.catalog_analyze import _advice


def test_no_finer_sensor_for_the_same_push_diameter_function():
    assert "no sensor tells them apart" in _advice({"same-push-diameter"})
    assert "finer sensor helps only" in _advice({"same-push-diameter", "tolerance"})
    assert _advice({"tolerance", "single-diameter"}).endswith("use a finer sensor")
