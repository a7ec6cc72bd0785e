"""semsegmap: segment-based semantic localization (SemSegMap) from Python.

The C++ library's bindings (semsegmap._semsegmap, python/src/), with nothing of their own: the
names, fields and errors are the library's. Arrays are numpy arrays; long calls release the GIL.

    import semsegmap as ssm
    ssm.keep_freed_memory_for_torch()  # once: faster learned descriptors (process-wide malloc)
    config = ssm.load_config(ssm.shipped_file("config/semsegmap.yaml"))
    mapping = ssm.open_dataset("sim:world=1,run=S1,preset=tiny")
    describer = ssm.describer_for(config.descriptor, mapping.info)
    built = ssm.run_mapping(mapping, config, describer, max_frames=60)
    query = ssm.open_dataset("sim:world=1,run=S2,preset=tiny")
    run = ssm.run_localization(query, config, built.map, describer, max_frames=60)
    print(run.summary().localizations, run.localizations[0].T_map_base)
"""

import os as _os

from ._semsegmap import *  # noqa: F401,F403 (the bindings are the package's API)
from ._semsegmap import WITH_PCL, WITH_ROS, WITH_SIM, WITH_TORCH, __version__  # noqa: F401
from . import _paths


def _holds_data(folder: str) -> bool:
    return _os.path.isfile(_os.path.join(folder, "config", "semsegmap.yaml"))


def data_dir() -> str:
    """The folder holding the shipped config/ and models/, found as the command line finds it
    (apps/semsegmap/resources.cpp): share/semsegmap beside an installed package, or else the
    source tree the module was built from. RuntimeError naming both when neither holds them."""
    here = _os.path.dirname(_os.path.abspath(__file__))
    installed = _os.path.normpath(_os.path.join(here, _paths.DATA_FROM_PACKAGE))
    for folder in (installed, _paths.SOURCE_DIR):
        if _holds_data(folder):
            return folder
    raise RuntimeError(
        f"cannot find semsegmap's configs and models: neither {installed} nor "
        f"{_paths.SOURCE_DIR} holds config/semsegmap.yaml (reinstall, or pass the files)")


def shipped_file(relative: str) -> str:
    """`relative` (e.g. "config/semsegmap.yaml") inside data_dir()."""
    return _os.path.join(data_dir(), relative)
