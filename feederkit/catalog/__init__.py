"""The parts catalog: SQLite (WAL, foreign keys, versioned schema), part revisions, changeovers.

Functions take a catalog as an open connection (:func:`open_catalog`) or a path; every write
is one transaction. See docs/catalog.md.
"""

from feederkit.catalog.bulk import DirectoryImport, import_directory, source_files
from feederkit.catalog.changeovers import (
    get_changeover,
    list_changeovers,
    remove_changeover,
    save_changeover,
)
from feederkit.catalog.model import (
    AddOutcome,
    Changeover,
    ChangeoverInfo,
    PartSummary,
    Revision,
    check_name,
)
from feederkit.catalog.schema import SCHEMA_VERSION, connect, migrate, schema_version
from feederkit.catalog.store import (
    CATALOG_ENV,
    DEFAULT_CATALOG,
    CatalogLike,
    add_file,
    add_outline,
    default_catalog_path,
    export_part,
    get_part,
    get_revision,
    list_parts,
    open_catalog,
    part_from_revision,
    part_names,
    remove_part,
    revision_history,
)

__all__ = [
    "CATALOG_ENV",
    "DEFAULT_CATALOG",
    "SCHEMA_VERSION",
    "AddOutcome",
    "CatalogLike",
    "Changeover",
    "ChangeoverInfo",
    "DirectoryImport",
    "PartSummary",
    "Revision",
    "add_file",
    "add_outline",
    "check_name",
    "connect",
    "default_catalog_path",
    "export_part",
    "get_changeover",
    "get_part",
    "get_revision",
    "import_directory",
    "list_changeovers",
    "list_parts",
    "migrate",
    "open_catalog",
    "part_from_revision",
    "part_names",
    "remove_changeover",
    "remove_part",
    "revision_history",
    "save_changeover",
    "schema_version",
    "source_files",
]
