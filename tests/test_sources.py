"""A SOURCE that is neither a file nor a catalog name is named as what it is (design.md)."""

from __future__ import annotations

import pytest

from feederkit.errors import InputError
from feederkit.sources import load_part


def test_a_missing_path_is_a_missing_file_not_a_missing_catalog_part(tmp_path) -> None:
    with pytest.raises(InputError, match=r"missing\.dxf: no such file$"):
        load_part(str(tmp_path / "drawings" / "missing.dxf"), catalog=str(tmp_path / "c.db"))


def test_a_name_too_long_for_the_file_system_is_one_line() -> None:
    with pytest.raises(InputError, match="cannot be a file"):
        load_part("x" * 300)


def test_a_plain_name_is_looked_up_in_the_catalog(tmp_path) -> None:
    with pytest.raises(InputError, match="no such file or catalog part"):
        load_part("l-brackt", catalog=str(tmp_path / "none.db"))
