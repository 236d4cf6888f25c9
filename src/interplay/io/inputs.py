"""Files read as input (motion clips, meshes): checked before they are opened."""
from __future__ import annotations

import stat
from pathlib import Path

from ..errors import InterplayError


def regular_file(path, max_bytes: int, what: str, error=InterplayError) -> Path:
    """``path`` if it is a regular file of at most ``max_bytes``; ``error`` naming the file
    otherwise. A FIFO, a device such as /dev/zero or a folder is refused before it is opened
    (reading one blocks forever or never ends)."""
    path = Path(path)
    try:
        st = path.stat()
    except OSError as e:
        raise error(f"{path}: cannot read {what} ({e.strerror or e})") from None
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{path}: not a regular file; a {what} must be a file")
    if st.st_size > max_bytes:
        raise error(f"{path}: {st.st_size / 2 ** 20:.0f} MiB is larger than the "
                    f"{max_bytes // 2 ** 20} MiB a {what} may have")
    return path
