"""Packets, the schema, encode/decode: the package's core over the C library.

Everything here goes through the C code the firmware links: the schema is
read from the library's ROM table at import (tase/schema.h), fields are
encoded and decoded by the typed codec (tase/codec.h), byte streams are
scanned by the greedy receiver (tase/frame.h) and JSON is formatted by the
bench tools' own formatter, so it is exactly what `tase --json` prints.
"""

import collections.abc
import decimal
import gc
import itertools
import math
import operator
import threading

from ._tase import ffi, lib

# Exact enough for any wire value (10 digits) of any float's repr (17
# significant digits) times a scale; ROUND_HALF_UP is "halves away from zero".
_DEC = decimal.Context(prec=60, rounding=decimal.ROUND_HALF_UP)


def _decimal(x):
    """The decimal a number was written as: an int exactly, a float as its
    shortest repr (1.005, though the double is just below it)."""
    return decimal.Decimal(float.__repr__(float(x)) if isinstance(x, float) else int(x))


def _scaled(value, mul, div=1):
    """value * mul / div (a finite int or float) as an int, rounded half away
    from zero on the decimal written: 1.005 deg * 100 is 101 cdeg."""
    x = _DEC.divide(_DEC.multiply(_decimal(value), _decimal(mul)), _decimal(div))
    return int(x.to_integral_value(rounding=decimal.ROUND_HALF_UP, context=_DEC))

__all__ = [
    "Error",
    "FieldError",
    "UnknownPacketError",
    "Field",
    "PacketType",
    "Packet",
    "PACKET_TYPES",
    "packet_type",
    "encode",
    "decode",
    "Decoder",
    "version",
    "LinkError",
    "TimeoutError_",
]

version = "%d.%d.%d" % (lib.TASE_VERSION_MAJOR, lib.TASE_VERSION_MINOR, lib.TASE_VERSION_PATCH)


# ---- errors ---------------------------------------------------------------


class Error(Exception):
    """An error of the library: `code` is the TASE_E* code (negative) or
    None, the message ends with the library's text for it."""

    def __init__(self, message, code=None):
        super().__init__(message)
        self.code = code


class FieldError(Error, ValueError):
    """A packet that cannot be built as asked: an unknown field, a value
    out of range, a field missing. Nothing was sent."""


class UnknownPacketError(Error, ValueError):
    """A packet name (or group/type) the schema does not know."""


class TimeoutError_(Error, TimeoutError):
    """No answer within the time allowed (TASE_ETIMEOUT)."""


class LinkError(Error, ConnectionError):
    """The link failed: the device went away, the peer hung up, I/O error."""


def strerror(code):
    return ffi.string(lib.tase_strerror(code)).decode()


def error(code, what, cls=None):
    """The exception for TASE_E* `code` with context `what`."""
    text = "%s: %s" % (what, strerror(code)) if what else strerror(code)
    if cls is None:
        if code == lib.TASE_ETIMEOUT:
            cls = TimeoutError_
        elif code in (lib.TASE_EIO, lib.TASE_ENODEV):
            cls = LinkError
        elif code == lib.TASE_EUNKNOWN:
            cls = UnknownPacketError
        elif code in (lib.TASE_ERANGE, lib.TASE_ELENGTH, lib.TASE_ETOOLONG, lib.TASE_EARG):
            cls = FieldError
        else:
            cls = Error
    return cls(text, code)


# ---- the schema ----------------------------------------------------------


class Field:
    """One field of a packet's table: name, width (bytes), signedness, the
    wire range, the "do not change" value (keep, or None), the
    "unavailable" value (none, or None: TAS 0xFFFF) and the engineering
    unit (unit: JSON key suffix such as "deg", or None; label; scale: unit
    per wire count; decimals printed by `tase --units`)."""

    __slots__ = (
        "name",
        "index",
        "width",
        "signed",
        "min",
        "max",
        "keep",
        "none",
        "unit",
        "label",
        "scale",
        "decimals",
        "_div",
        "depends",
    )

    def __repr__(self):
        unit = " [%s]" % self.label if self.unit is not None else ""
        return "<Field %s: %s%d bits%s>" % (
            self.name,
            "signed " if self.signed else "",
            8 * self.width,
            unit,
        )

    def to_eng(self, raw):
        """Wire integer -> engineering value (float when the field has a
        unit, else the integer)."""
        if self.unit is None:
            return raw
        if self._div:
            return raw / self._div
        return raw * self.scale

    def to_raw(self, value, pkt):
        """Engineering value -> wire integer, rounded half away from zero;
        FieldError when it is not a number or outside the field's range
        (never saturated: nothing is sent on a guess)."""
        if self.depends is not None:
            raise FieldError("%s %s: %s" % (pkt, self.name, self.depends))
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise FieldError("%s %s: not a number: %r" % (pkt, self.name, value))
        if isinstance(value, int) and abs(value) > 2**64:
            # far outside any field (a float of it raised OverflowError)
            raise FieldError("%s %s: %d is out of range" % (pkt, self.name, value), lib.TASE_ERANGE)
        if self.unit is None:
            if isinstance(value, float):
                if not value.is_integer():
                    raise FieldError(
                        "%s %s: %r is not an integer (the field has no unit: wire value)"
                        % (pkt, self.name, value)
                    )
                value = int(value)
            return self._check(value, pkt)
        if not math.isfinite(value):
            raise FieldError("%s %s: %r is not a finite number" % (pkt, self.name, value))
        r = _scaled(value, self._div) if self._div else _scaled(value, 1, self.scale)
        if not self.min <= r <= self.max:
            raise FieldError(
                "%s %s: %s %s out of range %s..%s %s"
                % (
                    pkt,
                    self.name,
                    value,
                    self.label,
                    self.to_eng(self.min),
                    self.to_eng(self.max),
                    self.label,
                ),
                lib.TASE_ERANGE,
            )
        if r == 0 and value != 0 and not self.signed:
            # an amount (unsigned: a rate limit, gain, filter, range) whose
            # 0 is none: AXIS_SETTING pan_max_rate 2 deg/s (steps of 5) is
            # raw 0, which locks the axis, SENSOR_FILTER cutoff 0.04 Hz a
            # 0 Hz filter; a request for something is not sent as nothing.
            # A signed value rounds to 0 as to any other (pan 0.004 deg).
            raise FieldError(
                "%s %s: %s %s is raw 0 (steps of %s %s): give 0 for 0, or at least half a step"
                % (pkt, self.name, value, self.label, self.to_eng(1), self.label),
                lib.TASE_ERANGE,
            )
        if r == self.keep or r == self.none:
            # e.g. AXIS_SETTING pan_max_rate 1275 deg/s is raw 0xFF: "do not
            # change", which a gimbal reads as no value at all
            raise FieldError(
                "%s %s: %s %s is raw %d, the wire's \"%s\" code, not a value "
                "(leave the field out, or give it in raw=, to send that code)"
                % (pkt, self.name, value, self.label, r,
                   "do not change" if r == self.keep else "unavailable"),
                lib.TASE_ERANGE,
            )
        return r

    def _check(self, value, pkt):
        if not isinstance(value, int) or isinstance(value, bool):
            raise FieldError("%s %s: not an integer: %r" % (pkt, self.name, value))
        if self.signed and self.keep is not None and self.keep < 0 and value == self.keep + (
            1 << (8 * self.width)
        ):
            # the "do not change" code as the spec writes it (hfov 0xFFFF is
            # -1), as the CLI takes it; no other pattern is wrapped
            value = self.keep
        if not self.min <= value <= self.max:
            raise FieldError(
                "%s %s: %d out of range %d..%d (%s %d-bit)"
                % (
                    pkt,
                    self.name,
                    value,
                    self.min,
                    self.max,
                    "signed" if self.signed else "unsigned",
                    8 * self.width,
                ),
                lib.TASE_ERANGE,
            )
        return value


class PacketType:
    """A packet of the spec, from the library's schema table: name, id,
    group, type, len (the table's data length), index (TASE_PKT_*),
    fields (in table order), to_gimbal / from_gimbal (direction),
    has_query (a zero-length form), tail (CAMERA_PASS's free bytes),
    reserved_flags (the bits of its flags field reserved in what is sent
    to the gimbal, as a mask, from tase_schema_reserved_flags(); 0 for
    none)."""

    __slots__ = (
        "name",
        "id",
        "group",
        "type",
        "len",
        "flags",
        "index",
        "fields",
        "by_name",
        "to_gimbal",
        "from_gimbal",
        "has_query",
        "tail",
        "reserved_flags",
        "_desc",
    )

    def __repr__(self):
        return "<PacketType %s 0x%02X/0x%02X, %d bytes, %d fields>" % (
            self.name,
            self.group,
            self.type,
            self.len,
            len(self.fields),
        )

    def length_ok(self, n):
        return bool(lib.tase_schema_length_ok(self._desc, n))

    def is_query(self, n):
        return bool(lib.tase_schema_is_query(self._desc, n))


# Fields whose unit another value decides: a number given for them by name
# (where other fields take engineering values) is refused, never guessed
# (GIMBAL_CMD pan=30 was sent as 0.30 degrees).
_DEPENDS = {
    ("GIMBAL_CMD", f): "its unit is set by flags (1/100 deg for a position, 1/100 deg/s for "
    "a rate): give the wire integer in raw= (raw={\"%s\": 4500} with flags 0xA0 is 45 deg), "
    "or use Link.point() / Link.rate()" % f
    for f in ("pan", "tilt", "roll")
}
_DEPENDS[("CAMERA_CMD", "hfov")] = (
    "its unit is set by its sign (1/100 deg of field of view, or minus 100 times a zoom "
    "ratio): give the wire integer in raw= (raw={\"hfov\": 1000} is 10 deg), or use "
    "Link.camera(hfov=..., zoom=...)"
)


def _load_schema():
    types = []
    out = ffi.new("py_field_t *")
    for i in range(lib.TASE_PKT_COUNT):
        d = lib.tase_schema_at(i)
        t = PacketType()
        t._desc = d
        t.name = ffi.string(lib.tase_schema_packet_name(d)).decode()
        t.id = d.id
        t.group = d.id >> 8
        t.type = d.id & 0xFF
        t.len = d.len
        t.flags = d.flags
        t.index = d.index
        t.to_gimbal = bool(d.flags & lib.TASE_DIR_IN)
        t.from_gimbal = bool(d.flags & lib.TASE_DIR_OUT)
        t.has_query = bool(d.flags & lib.TASE_LEN_QUERY)
        t.tail = bool(d.flags & lib.TASE_LEN_TAIL)
        t.reserved_flags = lib.tase_schema_reserved_flags(d)
        t.fields = []
        for k in range(d.nfields):
            if lib.py_field(i, k, d.len, out) != lib.TASE_OK:
                raise ImportError("tase: the schema of %s field %d cannot be read" % (t.name, k))
            f = Field()
            f.name = ffi.string(out.name).decode()
            f.index = k
            f.width = out.width
            f.signed = bool(out.is_signed)
            bits = 8 * f.width
            f.min = -(1 << (bits - 1)) if f.signed else 0
            f.max = (1 << (bits - 1)) - 1 if f.signed else (1 << bits) - 1
            f.keep = out.keep if out.has_keep else None
            f.none = None
            if out.has_unit and out.unavailable_ones:
                f.none = -1 if f.signed else f.max
            if out.has_unit:
                f.unit = ffi.string(out.unit_suffix).decode()
                f.label = ffi.string(out.unit_label).decode()
                f.scale = out.scale
                f.decimals = out.decimals
                inv = 1.0 / f.scale
                f._div = int(round(inv)) if abs(inv - round(inv)) < 1e-9 and inv >= 1 else 0
            else:
                f.unit = f.label = f.scale = f.decimals = None
                f._div = 0
            f.depends = _DEPENDS.get((t.name, f.name))
            t.fields.append(f)
        t.by_name = {f.name: f for f in t.fields}
        types.append(t)
    return types


PACKET_TYPES = _load_schema()
_BY_ID = {t.id: t for t in PACKET_TYPES}
_BY_NAME = {t.name: t for t in PACKET_TYPES}


def packet_type(name):
    """The PacketType of a spec name (case-insensitive), an id, or a
    PacketType; UnknownPacketError otherwise."""
    if isinstance(name, PacketType):
        return name
    if isinstance(name, int) and not isinstance(name, bool):
        if not 0 <= name <= 0xFFFF:
            # 0x10810 was "no packet 0x08/0x10", GIMBAL_ANGLE's id, which is
            raise UnknownPacketError(
                "%r is not a packet id (group << 8 | type, 0..0xFFFF)" % name, lib.TASE_EUNKNOWN
            )
        t = _BY_ID.get(name)
        if t is None:
            raise UnknownPacketError(
                "no packet 0x%02X/0x%02X in the schema" % (name >> 8, name & 0xFF),
                lib.TASE_EUNKNOWN,
            )
        return t
    if isinstance(name, str):
        t = _BY_NAME.get(name.upper())
        if t is not None:
            return t
    if isinstance(name, str) and name.upper() == "GIMBAL_TELEMETRY":
        # table 10's name, which 4.3.3 also gives GEOREFERENCE_DATA
        raise UnknownPacketError(
            "unknown packet name %r: table 10 gives it to 0x08/0x40, GIMBAL_RATE (4.2.2); "
            "4.3.3 calls GEOREFERENCE_DATA so too (PROTOCOL-NOTES D1)" % name,
            lib.TASE_EUNKNOWN,
        )
    raise UnknownPacketError(
        "unknown packet name %r (known: %s)" % (name, ", ".join(sorted(_BY_NAME))),
        lib.TASE_EUNKNOWN,
    )


# ---- packets ---------------------------------------------------------------

# A Packet is a tuple subclass, so that decode() builds millions of them at
# C speed (_Sink.take()): (key, offset, buf[, time_us, dir]) where key is
# id << 40 | data length << 32 | pos and the data bytes are
# buf[pos:pos + length].
_KEY, _OFF, _BUF, _TIME, _DIR = range(5)
_new_tuple = tuple.__new__
_M32 = 0xFFFFFFFF


class Packet(tuple):
    """One TASE packet (immutable).

    Build one with engineering values (degrees, m, m/s, s, ...) for the
    fields that have a unit and wire integers for the others:

        tase.Packet("GIMBAL_ANGLE", pan=12.5, tilt=-45, roll=0)
        tase.Packet("GIMBAL_CMD", raw={"pan": 4500, "tilt": -2000, "roll": 0},
                    flags=0xA0, impulse_time=0)    # pan/tilt/roll raw only: unit by flags
        tase.Packet("PACKET_RATE", raw={"angle_1": 20, ...})   # wire integers
        tase.Packet.query("SYSTEM_VERSION")                     # zero-length query

    Fields left out take the spec's "do not change" value when the field
    has one, `temporary` (PACKET_RATE, AXIS_SETTING) takes 1 (not stored by
    the gimbal, as `tase send`); any other missing field is a FieldError.
    Values out of range, unknown names and non-numbers are FieldError: a
    packet that exists is valid. Engineering values round half away from
    zero on the decimal written (pan=1.005 is 101). `length` selects a
    shorter accepted form (CAMERA_CMD 1: camera only; AXIS_SETTING 22: the
    short layout). CAMERA_PASS takes camera= (baud left out: 0, no change)
    and its camera bytes as data=b"...".

    Read: .name .group .type .id .size .fields (engineering values)
    .raw (wire integers) .units (the `--units` JSON values) .data
    (CAMERA_PASS bytes) .payload (the data bytes) .offset .time .dir
    .error ("wrong length" or None) .json().
    """

    __slots__ = ()

    def __new__(cls, name, *, raw=None, length=None, data=b"", **fields):
        t = packet_type(name)
        raw = _raw_arg(t.name, raw)
        for k, v in fields.items():
            f = t.by_name.get(k)
            if f is None:
                raise FieldError(
                    "%s has no field %r (fields: %s)"
                    % (t.name, k, ", ".join(x.name for x in t.fields) or "none")
                )
            if k in raw:
                raise FieldError("%s %s given twice (raw and engineering)" % (t.name, k))
            raw[k] = f.to_raw(v, t.name)
        return _make(t, raw, length, data)

    @classmethod
    def query(cls, name):
        """The zero-length form of a packet that has one (the query of a
        setup packet, SPOI_CMD or SYSTEM_VERSION; GYRO_ZERO_CMD)."""
        t = packet_type(name)
        if not t.length_ok(0):
            raise FieldError("%s has no zero-length form (no query)" % t.name, lib.TASE_ELENGTH)
        return _from_data(t.id, b"")

    @classmethod
    def from_data(cls, group, type, data, offset=0):
        """A packet of (group, type) carrying `data` as received (unknown
        packets and wrong lengths included). Group and type are 0..255 and
        data at most 253 bytes (what a frame can carry), else FieldError."""
        for what, v in (("group", group), ("type", type)):
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 0xFF:
                raise FieldError("from_data: %s %r is not 0..255" % (what, v))
        data = _bytes("from_data", data)
        if len(data) > lib.TASE_DATA_MAX:
            raise FieldError(
                "from_data: %d data bytes, a frame carries at most %d"
                % (len(data), lib.TASE_DATA_MAX),
                lib.TASE_ELENGTH,
            )
        if isinstance(offset, bool) or not isinstance(offset, int) or offset < 0:
            # "a" was taken, -5 failed only later in .json()
            raise FieldError("from_data: offset %r is not a stream offset (an int >= 0)" % (offset,))
        return _from_data(group << 8 | type, data, offset)

    offset = property(operator.itemgetter(_OFF), doc="stream offset of the first sync byte")

    @property
    def id(self):
        return self[_KEY] >> 40

    @property
    def size(self):
        """The data length (the frame's Size byte minus 2)."""
        return self[_KEY] >> 32 & 0xFF

    @property
    def group(self):
        return self[_KEY] >> 48

    @property
    def type(self):
        return self[_KEY] >> 40 & 0xFF

    @property
    def dir(self):
        """"in" (to the gimbal), "out" (from it), or None when unknown."""
        return self[_DIR] if len(self) > _DIR else None

    @property
    def packet_type(self):
        """The PacketType, or None for a packet the schema does not know."""
        return _BY_ID.get(self.id)

    @property
    def name(self):
        t = _BY_ID.get(self.id)
        return t.name if t is not None else "UNKNOWN"

    @property
    def payload(self):
        """The data bytes (what the frame carries between type and checksum)."""
        k = self[_KEY]
        p = k & _M32
        return self[_BUF][p : p + (k >> 32 & 0xFF)]

    @property
    def time(self):
        """Unix seconds (float) when the packet's last byte arrived, if known."""
        t = self[_TIME] if len(self) > _TIME else None
        return None if t is None else t / 1e6

    @property
    def time_us(self):
        """The time as integer Unix microseconds (what JSON prints), or None."""
        return self[_TIME] if len(self) > _TIME else None

    @property
    def error(self):
        t = _BY_ID.get(self.id)
        if t is not None and not t.length_ok(self.size):
            return "wrong length"
        return None

    @property
    def is_query(self):
        t = _BY_ID.get(self.id)
        return t is not None and t.is_query(self.size)

    @property
    def raw(self):
        """Wire integers by field name, in the spec's order (a query: {};
        a shorter form: the fields it carries; unknown packet: {"data":
        [bytes]}; wrong length: {})."""
        t = _BY_ID.get(self.id)
        if t is None:
            return {"data": list(self.payload)}
        data = self.payload
        vals = ffi.new("int64_t[]", len(t.fields) or 1)  # per call: threads
        n = lib.py_decode(t.index, data, len(data), vals, len(t.fields))
        if n < 0:
            return {}
        return dict(zip((f.name for f in t.fields[:n]), ffi.unpack(vals, n)))

    @property
    def fields(self):
        """Engineering values by field name (float in the field's unit:
        deg, deg/s, m, m/s, s, ...), wire integers where the field has no
        unit (flags, modes, GIMBAL_CMD's pan/tilt whose unit the flags
        select)."""
        t = _BY_ID.get(self.id)
        raw = self.raw
        if t is None:
            return raw
        by = t.by_name
        return {k: by[k].to_eng(v) for k, v in raw.items()}

    @property
    def units(self):
        """The engineering values `tase --units` adds: {"pan_deg": 12.34, ...};
        None for a field holding its "do not change" value (AXIS_SETTING's
        0xFF/0xFFFF) or its "unavailable" one (TAS 0xFFFF), as its null."""
        t = _BY_ID.get(self.id)
        if t is None:
            return {}
        out = {}
        for k, v in self.raw.items():
            f = t.by_name[k]
            if f.unit is not None:
                out[k + "_" + f.unit if f.unit else k] = (
                    None if v == f.keep or v == f.none else f.to_eng(v)
                )
        return out

    @property
    def data(self):
        """CAMERA_PASS: the camera bytes after the fields (else b"")."""
        t = _BY_ID.get(self.id)
        if t is None or not t.tail or self.size <= t.len:
            return b""
        return self.payload[t.len :]

    def replace(self, **fields):
        """A copy with some fields changed (engineering values; raw= too).
        A shorter form keeps its length: a field it does not carry is a
        FieldError (CAMERA_CMD's 1-byte form has only `camera`)."""
        t = _BY_ID.get(self.id)
        if t is None:
            raise UnknownPacketError("an unknown packet has no fields", lib.TASE_EUNKNOWN)
        raw = self.raw
        extra = _raw_arg(t.name, fields.pop("raw", None))
        data = fields.pop("data", self.data)
        twice = sorted(set(fields) & set(extra))
        if twice:
            # the raw value was kept silently; Packet() says "given twice"
            raise FieldError("%s: %s given twice (a value and in raw=)" % (t.name, ", ".join(twice)))
        for k, v in fields.items():
            f = t.by_name.get(k)
            if f is None:
                raise FieldError("%s has no field %r" % (t.name, k))
            raw[k] = f.to_raw(v, t.name)
        raw.update(extra)
        return _make(t, raw, self._form(t), data)

    def _form(self, t):
        """The length= that builds this packet's form again (None: the full one)."""
        return self.size if self.size != t.len and not t.tail else None

    def encode(self):
        """The complete frame (sync, size, group, type, data, checksum)."""
        return encode(self)

    def json(self, units=False):
        """The JSON object `tase --json` prints for this packet (one line,
        no newline): same keys, order and numbers. `units` is True or
        False ("no" or "false" is true in Python: they printed units)."""
        if not isinstance(units, bool):
            raise FieldError("json: units must be True or False, not %r" % (units,))
        return _json(self, units)

    def __eq__(self, other):
        if not isinstance(other, Packet):
            return NotImplemented
        return self[_KEY] >> 32 == other[_KEY] >> 32 and self.payload == other.payload

    def __ne__(self, other):
        r = self.__eq__(other)
        return r if r is NotImplemented else not r

    def __hash__(self):
        return hash((self.id, self.payload))

    def __repr__(self):
        t = _BY_ID.get(self.id)
        if t is None:
            return "<Packet UNKNOWN group=0x%02X type=0x%02X %d bytes>" % (
                self.group,
                self.type,
                self.size,
            )
        if not t.length_ok(self.size):
            return "<Packet %s: wrong length %d>" % (t.name, self.size)
        if t.is_query(self.size):
            return "Packet.query(%r)" % t.name
        args = ["%r" % t.name]
        codes = {}
        raw = self.raw
        for f in t.fields:
            if f.name in raw and (
                f.depends is not None or (f.unit is not None and raw[f.name] in (f.keep, f.none))
            ):
                codes[f.name] = raw[f.name]  # a code, or a field given raw only
        for k, v in self.fields.items():
            if k not in codes:
                args.append("%s=%r" % (k, v))
        if codes:
            args.append("raw=%r" % codes)
        if t.tail:
            args.append("data=%r" % self.data)
        if self._form(t) is not None:
            args.append("length=%d" % self.size)
        if _make(t, raw, self._form(t), self.data).payload != self.payload:
            # bytes no field holds (reserved, not zero, as received): the
            # fields alone made another packet (RETRACT_DEPLOY_CMD b7 66
            # came back as b7 00), so the data bytes themselves
            return "Packet.from_data(0x%02X, 0x%02X, %r)" % (self.group, self.type, self.payload)
        return "Packet(%s)" % ", ".join(args)

    def __reduce__(self):
        return (_from_data, (self.id, self.payload, self[_OFF], self.time_us, self.dir))


def _from_data(pid, data, offset=0, time_us=None, dir=None):
    key = pid << 40 | len(data) << 32
    if time_us is None and dir is None:
        return _new_tuple(Packet, (key, offset, data))
    return _new_tuple(Packet, (key, offset, data, time_us, dir))


def _with_meta(p, time_us, dir):
    """p with a time and direction."""
    return _new_tuple(Packet, (p[_KEY], p[_OFF], p[_BUF], time_us, dir))


def _raw_arg(name, raw):
    """raw= as a dict of wire integers by field name: None or a mapping
    ("ab" was a ValueError about a "dictionary update sequence", 5 a
    TypeError that named neither the packet nor raw=)."""
    if raw is None:
        return {}
    if not isinstance(raw, collections.abc.Mapping):
        raise FieldError(
            "%s: raw= takes a dict of wire integers by field name, not %s"
            % (name, type(raw).__name__)
        )
    return dict(raw)


def _bytes(what, data):
    """data as bytes: a bytes-like object (bytes(5) would be five zero
    bytes, and a str has no one encoding: both a TypeError)."""
    if data is None or isinstance(data, (int, str)):
        raise TypeError("%s takes bytes, not %s" % (what, type(data).__name__))
    try:
        return bytes(data)
    except (TypeError, ValueError) as e:
        # [300] or an object: "bytes must be in range(0, 256)" alone, or
        # "cannot convert 'X' object to bytes", did not say whose bytes
        raise type(e)("%s takes bytes: %s" % (what, e)) from None


def _make(t, raw, length, data):
    """Build packet type t from wire integers (by name) through the codec."""
    if length is None or (length == t.len and not isinstance(length, bool) and not t.tail):
        n = None
    else:
        if (
            isinstance(length, bool)
            or not isinstance(length, int)
            or not 0 <= length <= lib.TASE_DATA_MAX
            or not t.length_ok(length)
        ):
            raise FieldError("%s: %r is not an accepted data length" % (t.name, length))
        n = length
    for k in raw:
        if k not in t.by_name:
            raise FieldError(
                "%s has no field %r (fields: %s)"
                % (t.name, k, ", ".join(x.name for x in t.fields) or "none")
            )
    missing = []
    vals = []
    sent = set()
    if n == 0:
        if raw:
            raise FieldError("%s: a zero-length form carries no fields" % t.name)
    elif n is not None:
        # a shorter form: the fields that fit are sent (CAMERA_CMD: camera)
        tmp = ffi.new("py_field_t *")
        sent = {
            f.name
            for f in t.fields
            if lib.py_field(t.index, f.index, n, tmp) == 0
            and 0 <= tmp.offset
            and tmp.offset + f.width <= n
        }
        beyond = [k for k in raw if k not in sent]
        if beyond:
            # a given value the form cannot carry is never dropped silently
            raise FieldError(
                "%s: the %d-byte form carries only %s, not %s"
                % (t.name, n, ", ".join(f.name for f in t.fields if f.name in sent), ", ".join(beyond))
            )
    for f in t.fields:
        if f.name in raw:
            v = f._check(raw[f.name], t.name)
        elif n == 0 or (n is not None and f.name not in sent):
            v = f.keep if f.keep is not None else 0
        elif f.keep is not None:
            v = f.keep
        elif f.name == "temporary" and t.group == 0x48:
            v = 1
        else:
            missing.append(f.name)
            continue
        vals.append(v)
    if missing:
        raise FieldError("%s needs every field: missing %s" % (t.name, ", ".join(missing)))
    if data and not t.tail:
        raise FieldError("%s carries no data bytes" % t.name)
    if t.tail:
        data = _bytes("%s data" % t.name, data)
    enc = ffi.new("int64_t[]", vals or [0])
    out = ffi.new("uint8_t[]", lib.TASE_FRAME_MAX)
    bad = ffi.new("int *")
    r = lib.py_encode(
        t.index,
        enc,
        len(vals),
        data if data else ffi.NULL,
        len(data) if data else 0,
        ffi.cast("size_t", -1) if n is None else n,
        out,
        lib.TASE_FRAME_MAX,
        bad,
    )
    if r < 0:
        what = t.name
        if r == lib.TASE_ERANGE:
            what += " " + t.fields[bad[0]].name
        if r == lib.TASE_ETOOLONG:
            what += " data (%d bytes, at most %d)" % (len(data), lib.TASE_CAMERA_PASS_MAX)
        raise error(r, what)
    frame = ffi.buffer(out, r)[:]
    return _from_data(t.id, frame[6:-2])


def encode(packet):
    """The frame of `packet` (bytes): sync, Size, group, type, data and
    checksum, by the library's frame encoder."""
    if not isinstance(packet, Packet):
        raise TypeError("encode() takes a tase.Packet, not %s" % type(packet).__name__)
    data = packet.payload
    out = ffi.new("uint8_t[]", lib.TASE_FRAME_MAX)
    r = lib.tase_frame_build(packet.group, packet.type, data, len(data), out, lib.TASE_FRAME_MAX)
    if r < 0:
        raise error(r, "encode %s" % packet.name)
    return ffi.buffer(out, r)[:]


# ---- JSON ----------------------------------------------------------------

_json_lock = threading.Lock()
_json_buf = ffi.new("char[]", 8192)


def _json(p, units):
    t = p.time_us
    data = p.payload
    d = p.dir
    with _json_lock:  # tk_json.c caches per packet and the last lookup
        n = lib.py_json(
            _json_buf,
            8192,
            1 if units else 0,
            p[_OFF],
            0 if t is None else 1,
            0 if t is None else t // 1000000,
            0 if t is None else t % 1000000,
            ffi.NULL if d is None else (b"in" if d == "in" else b"out"),
            p.group,
            p.type,
            data,
            len(data),
        )
        return ffi.buffer(_json_buf, n)[:].decode().rstrip("\n")


# ---- decoding byte streams -------------------------------------------------

_alloc = ffi.new_allocator(should_clear_after_alloc=False)


class _Sink:
    """Columns the C helper fills with the frames a call delivers."""

    def __init__(self, nbytes, cap=None, timed=False):
        self.cap = cap if cap is not None else (nbytes + lib.TASE_FRAME_MAX) // 8 + 2
        self.dcap = nbytes + lib.TASE_FRAME_MAX + 1
        self.s = ffi.new("py_sink_t *")
        self.offset = _alloc("uint64_t[]", self.cap)
        self.key = _alloc("uint64_t[]", self.cap)
        self.data = _alloc("uint8_t[]", self.dcap)
        s = self.s
        s.offset, s.key, s.data = self.offset, self.key, self.data
        s.cap, s.dcap = self.cap, self.dcap
        self.time = None
        if timed:  # a time per frame: s.now when the receiver delivered it
            self.time = s.time = _alloc("uint64_t[]", self.cap)

    def take(self, time_us=None, dir=None):
        """The packets collected since the last take(), then empty; each
        with time_us (or, for a timed sink, the time of its delivery)."""
        s = self.s
        n = s.n
        if n == 0:
            return []
        buf = ffi.buffer(self.data, s.dlen)[:]
        keys = memoryview(ffi.buffer(self.key, 8 * n)).cast("Q")
        offs = memoryview(ffi.buffer(self.offset, 8 * n)).cast("Q")
        rep = itertools.repeat
        if self.time is not None:
            times = memoryview(ffi.buffer(self.time, 8 * n)).cast("Q")
            cols = zip(keys, offs, rep(buf), times, rep(dir))
        elif time_us is None and dir is None:
            cols = zip(keys, offs, rep(buf))
        else:
            cols = zip(keys, offs, rep(buf), rep(time_us), rep(dir))
        # millions of new tuples would run the cyclic collector over and
        # over: none of them can be part of a cycle
        enabled = gc.isenabled()
        gc.disable()
        try:
            out = list(map(_new_tuple, rep(Packet), cols))
        finally:
            if enabled:
                gc.enable()
        s.n = 0
        s.dlen = 0
        return out


def _check(r, what):
    if r < 0:
        raise error(r, what)
    return r


class DecodeResult(list):
    """The packets decode() found, in stream order, with .stats: the
    receiver's counters as `tase decode --stats` reports them."""

    def __init__(self, packets, rx_stats):
        super().__init__(packets)
        self._rx = rx_stats
        self._stats = None

    @property
    def stats(self):
        if self._stats is None:
            unknown = bad = 0
            for (pid, n), k in _count_pairs(self).items():
                t = _BY_ID.get(pid)
                if t is None:
                    unknown += k
                elif not t.length_ok(n):
                    bad += k
            st = dict(self._rx)
            st["frames"] = len(self)
            st["unknown"] = unknown
            st["bad_length"] = bad
            self._stats = st
        return self._stats


def _count_pairs(packets):
    import collections

    keys = collections.Counter(k >> 32 for k in map(operator.itemgetter(_KEY), packets))
    return {(k >> 8, k & 0xFF): n for k, n in keys.items()}


def _rx_stats(st, nbytes):
    return {
        "bytes": nbytes,
        "checksum_errors": st.checksum_errors,
        "bad_size": st.bad_size,
        "discarded": st.bytes_discarded,
    }


def decode(data):
    """Every packet in the byte string `data` (a raw serial capture), by the
    C receiver: the greedy scan of tase/frame.h, what is pending at the end
    settled (tase_rx_flush), exactly the frames and offsets `tase decode`
    prints. Returns a list of Packet (a DecodeResult, with .stats)."""
    if not isinstance(data, bytes):
        try:
            data = memoryview(data).cast("B")
        except TypeError:
            # "memoryview: a bytes-like object is required" named neither
            # decode() nor what it was given
            raise TypeError("decode() takes bytes, not %s" % type(data).__name__) from None
    n = len(data)
    rx = ffi.new("tase_rx_t *")
    _check(lib.tase_rx_init(rx), "decode")
    sink = _Sink(n)
    chunk = 1 << 30
    src = ffi.from_buffer(data)
    for i in range(0, n, chunk):
        k = min(chunk, n - i)
        _check(lib.py_rx_feed(rx, src + i, k, sink.s), "decode")
    _check(lib.py_rx_flush(rx, sink.s), "decode")
    if sink.s.dropped:
        raise Error("decode: %d frames lost (internal capacity)" % sink.s.dropped)
    return DecodeResult(sink.take(), _rx_stats(rx.stats, n))


def _time_us_arg(what, time_us):
    """time_us= of the packets a Decoder gives: None or an int of Unix
    microseconds (1.5 or "x" was taken, and failed later in .json() or
    .time, far from the call that gave it)."""
    if time_us is not None and (isinstance(time_us, bool) or not isinstance(time_us, int)):
        raise FieldError("%s: time_us %r is not an int of Unix microseconds (or None)" % (what, time_us))


class Decoder:
    """A stream decoder: feed() bytes as they come, get the packets they
    complete (a frame held behind a longer candidate comes later, as the
    receiver decides it); tick(now_ms) applies the receiver's time bound;
    flush() settles the end of input. `bytes_per_s` is the line's byte
    rate (baud / 10) for the time bound."""

    def __init__(self, bytes_per_s=5760, dir=None):
        if dir not in (None, "in", "out"):
            # "x" printed as "dir":"out"
            raise FieldError('Decoder: dir %r is not "in", "out" or None' % (dir,))
        if isinstance(bytes_per_s, bool) or not isinstance(bytes_per_s, int) or not (
            0 <= bytes_per_s <= 0xFFFFFFFF
        ):
            raise FieldError("Decoder: bytes_per_s %r is not a byte rate" % (bytes_per_s,))
        self.rx = ffi.new("tase_rx_t *")
        _check(lib.tase_rx_init(self.rx), "decoder")
        _check(lib.tase_rx_set_timing(self.rx, bytes_per_s, 0), "decoder")
        self.dir = dir
        self.bytes = 0
        self._sink = None
        self._cap = 0

    def _sink_for(self, n):
        if self._sink is None or self._cap < n:
            self._cap = max(n, 4096)
            self._sink = _Sink(self._cap)
            self._sink.s.base64 = self.bytes
        return self._sink

    def feed(self, data, time_us=None):
        data = _bytes("feed", data)
        _time_us_arg("feed", time_us)
        sink = self._sink_for(len(data))
        sink.s.base64 = self.bytes
        _check(lib.py_rx_feed(self.rx, data, len(data), sink.s), "feed")
        self.bytes += len(data)
        return sink.take(time_us, self.dir)

    def tick(self, now_ms, time_us=None):
        if isinstance(now_ms, bool) or not isinstance(now_ms, int):
            # 1.5 or None was a TypeError about "&"
            raise FieldError("tick: now_ms %r is not an int (the receiver's clock in ms)" % (now_ms,))
        _time_us_arg("tick", time_us)
        sink = self._sink_for(0)
        sink.s.base64 = self.bytes
        _check(lib.py_rx_tick(self.rx, now_ms & 0xFFFFFFFF, sink.s), "tick")
        return sink.take(time_us, self.dir)

    def flush(self, time_us=None):
        _time_us_arg("flush", time_us)
        sink = self._sink_for(0)
        sink.s.base64 = self.bytes
        _check(lib.py_rx_flush(self.rx, sink.s), "flush")
        return sink.take(time_us, self.dir)

    @property
    def stats(self):
        return _rx_stats(self.rx.stats, self.bytes)
