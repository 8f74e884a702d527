"""Import parts from CAD files: DXF drawings (ezdxf + shapely) and meshes (trimesh).

``import_parts(path, options, name)`` reads an outline ``.json``, ``.dxf``, ``.stl``,
``.obj`` or ``.ply`` file and returns the parts with their warnings and orientability.
"""

from feederkit.importers.model import (
    DEFAULT_FLATTEN_TOLERANCE,
    DEFAULT_HULL_TOLERANCE,
    DEFAULT_MAX_FILE_MB,
    SUPPORTED_SUFFIXES,
    ImportedOutline,
    ImportOptions,
    ImportResult,
    MeshPose,
)
from feederkit.importers.orientable import MIN_RESTING_RANGE_DEG, Orientability, orientability
from feederkit.importers.reader import (
    NOT_ORIENTABLE,
    ImportedPart,
    build_part,
    file_sha256,
    import_parts,
    read_source,
)

__all__ = [
    "DEFAULT_FLATTEN_TOLERANCE",
    "DEFAULT_HULL_TOLERANCE",
    "DEFAULT_MAX_FILE_MB",
    "MIN_RESTING_RANGE_DEG",
    "NOT_ORIENTABLE",
    "SUPPORTED_SUFFIXES",
    "ImportOptions",
    "ImportResult",
    "ImportedOutline",
    "ImportedPart",
    "MeshPose",
    "Orientability",
    "build_part",
    "file_sha256",
    "import_parts",
    "orientability",
    "read_source",
]
