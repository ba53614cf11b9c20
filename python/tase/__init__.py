"""tase: the Cloud Cap TASE gimbal protocol from Python, over the same C
library the firmware links (framing, the 21 packets, the receiver, the host
role). See docs/PYTHON.md.

    import tase
    with tase.sim.start() as sim, tase.connect(sim.url) as link:
        print(link.query("SYSTEM_VERSION"))
        link.point(45, -20)
"""

from ._core import (
    PACKET_TYPES,
    Decoder,
    Error,
    Field,
    FieldError,
    LinkError,
    Packet,
    PacketType,
    UnknownPacketError,
    decode,
    encode,
    packet_type,
    version,
)

__version__ = version

__all__ = [
    "__version__",
    "PACKET_TYPES",
    "Decoder",
    "Error",
    "Field",
    "FieldError",
    "LinkError",
    "Packet",
    "PacketType",
    "UnknownPacketError",
    "decode",
    "encode",
    "packet_type",
]

from . import capture, plot, sim  # noqa: E402
from .capture import CaptureError, read_capture  # noqa: E402
from .link import Link, connect, parse_url  # noqa: E402

__all__ += ["capture", "plot", "sim", "CaptureError", "Link", "connect", "parse_url", "read_capture"]
