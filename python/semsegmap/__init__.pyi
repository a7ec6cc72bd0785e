# Type stubs of the package: the bindings (_semsegmap.pyi) and the shipped files' finder.
from ._semsegmap import *
from ._semsegmap import WITH_PCL as WITH_PCL
from ._semsegmap import WITH_ROS as WITH_ROS
from ._semsegmap import WITH_SIM as WITH_SIM
from ._semsegmap import WITH_TORCH as WITH_TORCH
from ._semsegmap import __version__ as __version__

def data_dir() -> str: ...
def shipped_file(relative: str) -> str: ...
