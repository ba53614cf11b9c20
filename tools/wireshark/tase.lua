-- tase.lua: Wireshark dissector for the Cloud Cap TASE gimbal protocol
-- (Wireshark 3.x/4.x, its Lua 5.2 API).
--
-- Load it for one run:
--     wireshark -X lua_script:tools/wireshark/tase.lua capture.pcap
--     tshark -2 -X lua_script:tools/wireshark/tase.lua -r capture.pcap -O tase
-- (-2: see "Each frame is shown..." below for why tshark needs two passes)
-- or for good: copy it into the personal Lua plugin folder
-- (~/.local/lib/wireshark/plugins/; Help > About > Folders shows it).
--
-- What it dissects:
--   * TASE over CAN: Wireshark's own CAN dissector hands it the payload of
--     extended frames 0x10000000 (from the gimbal, "dir" "out") and
--     0x11000000 (to the gimbal, "dir" "in"), whose datalink bytes it
--     reassembles per direction (and per capture interface) across frames,
--     and the 3AX drive frames 0x12010000 (move command) and 0x12020000
--     (status). Works on candump logs (tshark reads them directly), pcap
--     and pcapng captures with LINKTYPE_CAN_SOCKETCAN (`tase record --can`).
--   * `tase record --serial` captures: link type LINKTYPE_USER0 (147),
--     each record a one-byte direction pseudo-header (0x00 from the gimbal,
--     0x01 to the gimbal; anything else is flagged) followed by the bytes
--     as read. Registered for that link type directly: no "DLT_USER"
--     preference is needed.
--
-- Every TASE packet gets a "tase" tree named as in `tase list`, with the
-- keys of `tase decode`'s JSON as filter fields: tase.offset, tase.dir,
-- tase.group, tase.type, tase.name, tase.size (the data length), the
-- packet's fields as tase.<packet name in lower case>.<field> with the raw
-- wire integers (e.g. tase.gimbal_angle.pan), tase.data for CAMERA_PASS's
-- camera bytes and an unknown packet's data, and tase.error "wrong length"
-- for a valid frame whose data length its type does not accept. Filter
-- examples: tase.name == "GIMBAL_CMD", tase.gimbal_angle.tilt < -4500.
--
-- Reassembly follows the library's receiver (tase/frame.h) exactly, so
-- that Wireshark and `tase decode` show the same frames: per stream (the
-- serial direction; the CAN direction per capture interface) the greedy
-- scan from the start of the capture: at each position a complete frame
-- with a valid checksum (00 FF 5A, Size >= 2, Size + 6 bytes) is taken and
-- the scan continues after its last byte, anywhere else it moves on one
-- byte. Nothing inside a shown frame is shown (a CAMERA_PASS whose camera
-- bytes hold a valid frame gives the CAMERA_PASS only), and no frame is
-- lost behind a corrupted Size byte, a false sync or noise.
--
-- Each frame is shown in the record or CAN frame that carries its LAST
-- byte, with that packet's time: `tase decode`'s "time". A frame that lies
-- inside a longer candidate still pending (a Size byte corrupted upwards,
-- say) is only known once a later packet makes that candidate fail (at
-- most 253 bytes later), so the first pass (pinfo.visited false) records
-- per packet number which frames end there, and they are shown when the
-- packet is dissected again: the GUI re-dissects a packet when it is
-- selected, tshark does with -2 (two-pass analysis), and a held frame
-- then carries tase.decided_in, the packet whose bytes decided it. A
-- candidate still pending at the end of the capture fails as in
-- tase_rx_flush() (tase.decided_at_end on what it was hiding). A
-- single-pass tshark (no -2) only has the first pass: there a held frame
-- is shown in the packet that decided it, with tase.last_byte_in naming
-- the packet of its last byte (and so another time than `tase decode`'s),
-- and frames hidden by a candidate pending at the end of the capture are
-- not shown. Use `tshark -2`. tase.offset counts the bytes of the frame's
-- stream from the start of the capture, as `tase decode` does.
--
-- Interfaces: the capture interface of a packet (frame.interface_id) is a
-- field value, and field values exist only in a pass that builds a
-- protocol tree; tshark -2 builds none in its first pass unless given a
-- filter, so there every interface is reassembled as one and the second
-- pass flags packets of another interface with the expert warning
-- tase.interfaces_merged: for a pcapng of several interfaces run
-- `tshark -2 -R frame`. (The CAN ID comes from pinfo.match_uint, always
-- there.) Wireshark 4.0's candump reader drops interface names, so a
-- candump log with TASE traffic on several interfaces is reassembled as
-- one bus; `tase decode --candump` keeps them apart.

local tase = Proto("tase", "TASE gimbal protocol")
local tase_serial = Proto("tase_serial", "TASE serial capture")
-- A serial capture's line rate: `tase decode --baud`'s (the time bound of
-- reassembly below). tshark: -o tase.baud:9600.
tase.prefs.baud = Pref.uint("Serial line baud rate", 57600,
    "The rate of the captured serial line (as tase decode --baud): a pending candidate frame "
        .. "is judged false after a gap longer than its remaining bytes' time at this rate, "
        .. "at least the quiet margin")
-- The least gap that ends a pending candidate: `tase decode --margin`'s
-- (can.h PAUSES: a CAN link whose frames come further apart needs more).
-- tshark: -o tase.margin:250.
tase.prefs.margin = Pref.uint("Quiet margin (ms)", 20,
    "The least gap, in milliseconds, after which a pending candidate frame is judged false "
        .. "(as tase decode --margin MS; default 20, the receiver's; 0 is taken as 20)")

-- BEGIN GENERATED (tools/wireshark/schema_lua.c; do not edit by hand)
-- {group, type, name, data length, flags,
--  {{field, offset, width, signed[, shift]}...}}
-- flags: q = zero-length query form, 1 = one-byte form, t = free bytes after
-- the fields (CAMERA_PASS), s = a short layout one byte shorter, where the
-- fields marked shift sit one byte earlier (AXIS_SETTING's 22 bytes)
local SCHEMA = {
    {0x00, 0x80, "GIMBAL_CMD", 8, "", {
        {"pan", 0, 2, true}, {"tilt", 2, 2, true}, {"roll", 4, 2, true},
        {"flags", 6, 1, false}, {"impulse_time", 7, 1, false},
    }},
    {0x00, 0x40, "GYRO_ZERO_CMD", 0, "", {}},
    {0x00, 0x41, "CAMERA_CMD", 10, "1", {
        {"camera", 0, 1, false}, {"hfov", 2, 2, true}, {"focus", 4, 2, false},
        {"exposure", 6, 1, false}, {"shutter_speed", 7, 1, false}, {"bright", 8, 1, false},
        {"flags", 9, 1, false},
    }},
    {0x00, 0x81, "LEGACY_CAMERA_CMD", 8, "", {
        {"zoom", 0, 2, false}, {"focus", 2, 2, false}, {"auto_exposure", 4, 1, false},
        {"shutter_speed", 5, 1, false}, {"iris", 6, 1, false}, {"gain", 7, 1, false},
    }},
    {0x00, 0x42, "CAMERA_PASS", 4, "t", {
        {"camera", 0, 1, false}, {"baud", 1, 1, false},
    }},
    {0x00, 0x43, "RETRACT_DEPLOY_CMD", 2, "", {
        {"deploy", 0, 1, false},
    }},
    {0x08, 0x10, "GIMBAL_ANGLE", 6, "", {
        {"pan", 0, 2, true}, {"tilt", 2, 2, true}, {"roll", 4, 2, true},
    }},
    {0x08, 0x40, "GIMBAL_RATE", 18, "", {
        {"time", 0, 4, false}, {"pan_rate", 4, 2, true}, {"tilt_rate", 6, 2, true},
        {"roll_rate", 8, 2, true}, {"p", 10, 2, true}, {"q", 12, 2, true},
        {"r", 14, 2, true}, {"mode", 17, 1, false},
    }},
    {0x08, 0x41, "HOST_SENSOR", 20, "", {
        {"time", 0, 4, false}, {"roll", 4, 2, true}, {"pitch", 6, 2, true},
        {"yaw", 8, 2, true}, {"flags", 10, 1, false}, {"sample_rate", 11, 1, false},
        {"x_accel", 12, 2, true}, {"y_accel", 14, 2, true}, {"z_accel", 16, 2, true},
        {"tas", 18, 2, false},
    }},
    {0x08, 0x42, "HOST_ATTITUDE", 12, "", {
        {"time", 0, 4, false}, {"roll", 4, 2, true}, {"pitch", 6, 2, true},
        {"yaw", 8, 2, true}, {"flags", 10, 1, false}, {"sample_rate", 11, 1, false},
    }},
    {0x10, 0x10, "HOST_GPS_DATA", 32, "", {
        {"time", 0, 4, false}, {"lat", 4, 4, true}, {"lon", 8, 4, true},
        {"height", 12, 4, true}, {"vnorth", 16, 2, true}, {"veast", 18, 2, true},
        {"vdown", 20, 2, true}, {"year", 22, 2, false}, {"month", 24, 1, false},
        {"day", 25, 1, false}, {"hour", 26, 1, false}, {"minute", 27, 1, false},
        {"second", 28, 1, false}, {"frac_second", 29, 1, false}, {"valid", 30, 1, false},
        {"sample_rate", 31, 1, false},
    }},
    {0x10, 0x40, "SPOI_CMD", 19, "q", {
        {"lat", 0, 4, true}, {"lon", 4, 4, true}, {"height", 8, 4, true},
        {"vnorth", 12, 2, true}, {"veast", 14, 2, true}, {"vdown", 16, 2, true},
        {"flags", 18, 1, false},
    }},
    {0x10, 0x41, "GEOREFERENCE_DATA", 63, "", {
        {"time", 0, 4, false}, {"lat", 4, 4, true}, {"lon", 8, 4, true},
        {"height", 12, 4, true}, {"vnorth", 16, 2, true}, {"veast", 18, 2, true},
        {"vdown", 20, 2, true}, {"year", 22, 2, false}, {"month", 24, 1, false},
        {"day", 25, 1, false}, {"hour", 26, 1, false}, {"minute", 27, 1, false},
        {"second", 28, 1, false}, {"frac_second", 29, 1, false}, {"num_sats", 30, 1, false},
        {"pdop", 31, 1, false}, {"status", 32, 2, false}, {"camera_roll", 34, 2, true},
        {"camera_pitch", 36, 2, true}, {"camera_yaw", 38, 2, true}, {"hfov", 40, 2, false},
        {"vfov", 42, 2, false}, {"focal", 44, 2, false}, {"mode", 46, 1, false},
        {"sample_rate", 47, 1, false}, {"nav_health", 48, 2, false}, {"mount_roll", 50, 2, true},
        {"mount_pitch", 52, 2, true}, {"mount_yaw", 54, 2, true}, {"pan", 56, 2, true},
        {"tilt", 58, 2, true}, {"roll", 60, 2, true}, {"camera", 62, 1, false},
    }},
    {0x48, 0x00, "PACKET_RATE", 16, "q", {
        {"angle_1", 0, 1, false}, {"rate_1", 1, 1, false}, {"geo_ref_1", 2, 1, false},
        {"camera_1", 3, 1, false}, {"angle_2", 5, 1, false}, {"rate_2", 6, 1, false},
        {"geo_ref_2", 7, 1, false}, {"camera_2", 8, 1, false}, {"angle_3", 10, 1, false},
        {"rate_3", 11, 1, false}, {"geo_ref_3", 12, 1, false}, {"camera_3", 13, 1, false},
        {"temporary", 15, 1, false},
    }},
    {0x48, 0x01, "SENSOR_FILTER", 2, "q", {
        {"cutoff", 0, 1, false}, {"decimation", 1, 1, false},
    }},
    {0x48, 0x02, "AXIS_SETTING", 23, "qs", {
        {"pan_nogo_center", 0, 2, true}, {"pan_nogo_range", 2, 2, false}, {"tilt_nogo_center", 4, 2, true},
        {"tilt_nogo_range", 6, 2, false}, {"roll_nogo_center", 8, 2, true}, {"roll_nogo_range", 10, 2, false},
        {"pan_max_rate", 12, 1, false}, {"tilt_max_rate", 14, 1, false, true}, {"roll_max_rate", 15, 1, false, true},
        {"pan_max_accel", 16, 1, false, true}, {"tilt_max_accel", 17, 1, false, true}, {"roll_max_accel", 18, 1, false, true},
        {"pan_pos_gain", 19, 1, false, true}, {"tilt_pos_gain", 20, 1, false, true}, {"roll_pos_gain", 21, 1, false, true},
        {"temporary", 22, 1, false, true},
    }},
    {0x48, 0x03, "SYSTEM_VERSION", 42, "q", {
        {"major", 0, 1, false}, {"minor", 1, 1, false}, {"sub", 2, 1, false},
        {"released", 3, 1, false}, {"soft_year", 4, 2, false}, {"soft_month", 6, 1, false},
        {"soft_day", 7, 1, false}, {"board_sn", 8, 4, false}, {"board_rev", 12, 4, false},
        {"board_config", 16, 4, false}, {"board_year", 20, 2, false}, {"board_month", 22, 1, false},
        {"board_day", 23, 1, false}, {"camera_a", 24, 1, false}, {"max_hfov_a", 26, 2, false},
        {"min_hfov_a", 28, 2, false}, {"camera_b", 30, 1, false}, {"max_hfov_b", 32, 2, false},
        {"min_hfov_b", 34, 2, false}, {"camera_c", 36, 1, false}, {"max_hfov_c", 38, 2, false},
        {"min_hfov_c", 40, 2, false},
    }},
    {0x48, 0x04, "NAV_SOURCE", 2, "q", {
        {"external_attitude", 0, 1, false}, {"external_gps", 1, 1, false},
    }},
    {0x48, 0x05, "CAMERA_TYPE", 3, "q", {
        {"camera_a", 0, 1, false}, {"camera_b", 1, 1, false}, {"camera_c", 2, 1, false},
    }},
    {0x48, 0x06, "GPS_LEVER_ARM", 6, "q", {
        {"x", 0, 2, true}, {"y", 2, 2, true}, {"z", 4, 2, true},
    }},
    {0x48, 0x07, "CAMERA_ALIGN", 16, "q", {
        {"zoom_1", 0, 2, false}, {"pan_err_1", 2, 2, true}, {"tilt_err_1", 4, 2, true},
        {"roll_err_1", 6, 2, true}, {"zoom_2", 8, 2, false}, {"pan_err_2", 10, 2, true},
        {"tilt_err_2", 12, 2, true}, {"roll_err_2", 14, 2, true},
    }},
}
-- END GENERATED

local SYNC = "\0\255\90" -- 00 FF 5A
-- the byte rate of the CAN encapsulation at 1 Mbit/s (tase/socketcan.h)
local CAN_BYTES_PER_S = 50000
local DIR_NAMES = {[0] = "out", [1] = "in"} -- serial pseudo-header values
local CAN_DIRS = {[0x10000000] = "out", [0x11000000] = "in"}
local ID_3AX_MOVE, ID_3AX_STATUS = 0x12010000, 0x12020000

local F = {
    dir = ProtoField.string("tase.dir", "dir"),
    offset = ProtoField.uint64("tase.offset", "offset"),
    group = ProtoField.uint8("tase.group", "group", base.HEX),
    type = ProtoField.uint8("tase.type", "type", base.HEX),
    name = ProtoField.string("tase.name", "name"),
    size = ProtoField.uint8("tase.size", "size"),
    checksum = ProtoField.uint16("tase.checksum", "checksum", base.HEX),
    data = ProtoField.bytes("tase.data", "data"),
    error = ProtoField.string("tase.error", "error"),
    decided_in = ProtoField.framenum("tase.decided_in",
        "held until frame (where the longer candidate covering it failed)"),
    decided_at_end = ProtoField.bool("tase.decided_at_end",
        "held until the end of the capture (the longer candidate covering it never completed)"),
    last_byte_in = ProtoField.framenum("tase.last_byte_in",
        "last byte in frame (one pass only: shown where it was decided; use tshark -2)"),
    move_position = ProtoField.uint8("tase.3ax_move.position", "position (0 deploy, else retract)"),
    status_position = ProtoField.uint8("tase.3ax_status.position",
        "position (0 deployed .. 254 retracted, 255 unknown)"),
    status_speed = ProtoField.int8("tase.3ax_status.speed", "speed (units of 5 deg/s)"),
    serial_dir = ProtoField.uint8("tase_serial.dir", "direction", base.HEX,
        {[0] = "from the gimbal (out)", [1] = "to the gimbal (in)"}),
    serial_bytes = ProtoField.bytes("tase_serial.bytes", "bytes"),
}
local E = {
    bad_dir = ProtoExpert.new("tase_serial.bad_dir", "unknown direction byte",
        expert.group.MALFORMED, expert.severity.ERROR),
    wrong_length = ProtoExpert.new("tase.wrong_length", "wrong data length for this packet type",
        expert.group.MALFORMED, expert.severity.WARN),
    no_bytes = ProtoExpert.new("tase_serial.no_bytes", "no datalink bytes in the record "
        .. "(tase decode skips such a record as bad)", expert.group.MALFORMED,
        expert.severity.ERROR),
    merged = ProtoExpert.new("tase.interfaces_merged", "reassembled with the streams of every " ..
        "capture interface merged: the first pass had no protocol tree (use tshark -2 -R frame)",
        expert.group.REASSEMBLE, expert.severity.WARN),
}

-- Packet table keyed by group * 256 + type, with a ProtoField per field.
local PACKETS = {}
local field_list = {}
for _, f in pairs(F) do
    if f ~= F.serial_dir and f ~= F.serial_bytes then field_list[#field_list + 1] = f end
end
for _, row in ipairs(SCHEMA) do
    local p = {group = row[1], type = row[2], name = row[3], len = row[4], flags = row[5], fields = {}}
    for _, fr in ipairs(row[6]) do
        local abbr = "tase." .. row[3]:lower() .. "." .. fr[1]
        local ctor = (fr[4] and "int" or "uint") .. (8 * fr[3])
        local pf = ProtoField[ctor](abbr, fr[1])
        p.fields[#p.fields + 1] = {name = fr[1], offset = fr[2], width = fr[3], shift = fr[5], pf = pf}
        field_list[#field_list + 1] = pf
    end
    PACKETS[row[1] * 256 + row[2]] = p
end
tase.fields = field_list
tase_serial.fields = {F.serial_dir, F.serial_bytes}
tase.experts = {E.wrong_length, E.merged}
tase_serial.experts = {E.bad_dir, E.no_bytes}

-- Whether len selects the packet's short layout (tase/schema.h, TWO
-- LAYOUTS; docs/PROTOCOL-NOTES.md S2).
local function short_layout(p, len)
    return len + 1 == p.len and p.flags:find("s", 1, true) ~= nil
end

-- The data lengths a packet accepts (tase_schema_length_ok()).
local function length_ok(p, len)
    return len == p.len or (len == 0 and p.flags:find("q", 1, true) ~= nil)
        or (len == 1 and p.flags:find("1", 1, true) ~= nil)
        or (len >= p.len and p.flags:find("t", 1, true) ~= nil)
        or short_layout(p, len)
end

-- ---- reassembly, one stream per direction and interface ----

-- The first pass's results, per packet number: the frames whose last byte
-- the packet carries (`ended`, shown when it is dissected again) and the
-- frames its bytes decided (`decided`, shown by a single pass). A frame is
-- {off, raw, last = packet of its last byte, decided = deciding packet or
-- nil (end of capture)}. `tails`: per packet, the frames an end-of-capture
-- flush of its stream would give, recomputed while the capture grows.
local streams, ended, decided, tails
local ifaces -- packet number -> the capture interface its stream was keyed by
local last_ts -- the time of the last packet fed (any stream), for one without

-- Called by Wireshark before each (re)dissection of a capture.
local function reset()
    streams = {} -- key -> {buf, base, pos, hist, dirty, tail_nums}
    ended, decided, tails, ifaces = {}, {}, {}, {}
    last_ts = nil
end
tase.init = reset
reset()

local function checksum_ok(raw)
    local sum, n = 0, #raw
    for i = 1, n - 2 do sum = sum + raw:byte(i) end
    return sum % 65536 == raw:byte(n - 1) * 256 + raw:byte(n)
end

-- The packet that carried the byte before stream offset `stop`.
local function packet_of(st, stop)
    for _, h in ipairs(st.hist) do
        if h.stop >= stop then return h.num end
    end
    return st.hist[#st.hist].num
end

-- The greedy scan of st.buf (stream offsets st.base..) from st.pos,
-- appending the frames it takes to `out`. It stops at a candidate that is
-- not complete yet (st.pos stays on it), unless `final`: then, as at
-- tase_rx_flush(), that candidate fails and the scan goes on after its
-- first byte. Leaves st.pos where the next call must resume.
local function scan(st, final, out)
    local top = st.base + #st.buf
    while true do
        local i = st.buf:find(SYNC, st.pos - st.base + 1, true)
        if i == nil then
            st.pos = math.max(st.pos, top - 2) -- a partial sync may follow
            return
        end
        local s = st.base + i - 1
        local size = st.buf:byte(i + 3)
        st.pos = s
        if size ~= nil and size >= 2 and s + size + 6 <= top then
            local raw = st.buf:sub(i, i + size + 5)
            if checksum_ok(raw) then
                out[#out + 1] = {off = s, raw = raw, last = packet_of(st, s + size + 6)}
                st.pos = s + size + 6
            else
                st.pos = s + 1
            end
        elseif size ~= nil and size < 2 then
            st.pos = s + 1 -- Size < 2: no frame
        elseif final then
            st.pos = s + 1 -- can no longer complete
        else
            return -- pending: what follows waits for it
        end
    end
end

-- The live receiver's time bound (tase/frame.h, TIME BOUND), applied to
-- the packets' times as `tase decode` applies it: what a stream holds (a
-- pending candidate, or a partial sync at its end) is judged false, as at
-- the end of the capture, when the next packet of the stream comes more
-- than its quiet limit after the previous one: the time its remaining
-- bytes need at the line's rate, at least the margin preference (20 ms
-- unless set, as tase decode's --margin).
local FRAME_MAX = 261

-- A packet time (seconds, a double) in whole milliseconds, as `tase
-- decode` truncates a record's time. The double holds a time near 1.7e9 s
-- to about 0.12 us, so 0.15 us guards its rounding down, added to the
-- fraction alone (ts * 1000 is a double of 0.24 us steps, and a guard of
-- 0.5 us on it rounded 20.9996 ms up to 21 where tase decode says 20: a
-- pause judged differently). Only a nanosecond capture's time within
-- about 0.15 us below a millisecond can still read as the next one.
local function ms_of(ts)
    local s = math.floor(ts)
    return s * 1000 + math.floor((ts - s) * 1000 + 0.00015)
end

-- The quiet limit of what stream `st` holds, or nil when it holds nothing.
local function quiet_limit(st, rate)
    local i = st.pos - st.base + 1
    local held, left = #st.buf - i + 1, nil
    if held >= 4 then -- a pending candidate (the scan stopped on it)
        left = st.buf:byte(i + 3) + 6 - held
    else -- the longest end of the buffer that begins a sync
        for k = math.min(held, 3), 1, -1 do
            if st.buf:sub(-k) == SYNC:sub(1, k) then
                left = FRAME_MAX - k
                break
            end
        end
        if left == nil then return nil end
    end
    local margin = tase.prefs.margin
    if margin == 0 then margin = 20 end -- the receiver takes 0 as its default
    return math.max(math.floor((left * 1000 + rate - 1) / rate), margin)
end

-- First pass: append packet `num`'s bytes (arrived at `ts` on a line of
-- `rate` bytes/s) to stream `key` and record the frames they decide, in
-- stream order.
local function feed(key, chunk, num, ts, rate)
    local st = streams[key]
    if st == nil then
        st = {buf = "", base = 0, pos = 0, hist = {}, tail_nums = {}}
        streams[key] = st
    end
    if ts == 0 and last_ts ~= nil then
        -- a pcapng Simple Packet Block has no time (Wireshark gives 0):
        -- the time of the packet before it, of any stream, as tase decode
        -- takes it (the packet came after that one; from 1970, the gap cut
        -- a frame split across it)
        ts = last_ts
    end
    last_ts = ts
    local out, now = {}, ms_of(ts)
    if st.last_ms ~= nil then
        local limit = quiet_limit(st, rate)
        if limit ~= nil and now - st.last_ms > limit then
            scan(st, true, out) -- the line went quiet on it
            st.pos = st.base + #st.buf
        end
    end
    st.last_ms = now
    st.buf = st.buf .. chunk
    st.hist[#st.hist + 1] = {stop = st.base + #st.buf, num = num}
    scan(st, false, out)
    st.buf = st.buf:sub(st.pos - st.base + 1)
    st.base = st.pos
    while st.hist[1] ~= nil and st.hist[1].stop <= st.base and #st.hist > 1 do
        table.remove(st.hist, 1)
    end
    for _, fr in ipairs(out) do
        fr.decided = num
        ended[fr.last] = ended[fr.last] or {}
        table.insert(ended[fr.last], fr)
    end
    decided[num] = out
    st.dirty = true
end

-- What the end of the capture decides: for each stream fed since the last
-- call, a flush of a copy of its state, filed by the packet of each
-- frame's last byte (none of them has a deciding packet).
local function settle()
    for _, st in pairs(streams) do
        if st.dirty then
            for _, num in ipairs(st.tail_nums) do tails[num] = nil end
            st.tail_nums = {}
            local out = {}
            scan({buf = st.buf, base = st.base, pos = st.pos, hist = st.hist}, true, out)
            for _, fr in ipairs(out) do
                if tails[fr.last] == nil then
                    tails[fr.last] = {}
                    st.tail_nums[#st.tail_nums + 1] = fr.last
                end
                table.insert(tails[fr.last], fr)
            end
            st.dirty = false
        end
    end
end

-- ---- display ----

-- A data field, also of no bytes (shown as "none", not Wireshark's
-- <MISSING>): the unknown packet's and CAMERA_PASS's camera bytes.
local function add_data(t, range)
    local item = t:add(F.data, range)
    if range:len() == 0 then item:set_text("data: none") end
end

local function add_frame(tree, fr, dir)
    local ftvb = ByteArray.new(fr.raw, true):tvb("TASE frame")
    local group, ptype, sizeb = ftvb(4, 1):uint(), ftvb(5, 1):uint(), ftvb(3, 1):uint()
    local len = sizeb - 2
    local p = PACKETS[group * 256 + ptype]
    local name = p and p.name or "UNKNOWN"
    local t = tree:add(tase, ftvb(), string.format("TASE %s (0x%02X/0x%02X), %d data bytes, %s",
        name, group, ptype, len, dir == "in" and "to the gimbal" or "from the gimbal"))
    t:add(F.offset, ftvb(0, 3), UInt64.new(fr.off)):set_generated()
    t:add(F.dir, dir):set_generated()
    t:add(F.group, ftvb(4, 1))
    t:add(F.type, ftvb(5, 1))
    t:add(F.name, ftvb(4, 2), name)
    t:add(F.size, ftvb(3, 1), len)
    if p == nil then -- its data, however short (none: an empty field, as decode's "data":[])
        add_data(t, ftvb(6, len))
    elseif not length_ok(p, len) then
        t:add(F.error, ftvb(3, 1), "wrong length")
        t:add_proto_expert_info(E.wrong_length)
    else
        local short = short_layout(p, len)
        for _, f in ipairs(p.fields) do
            local at = (short and f.shift and f.offset > 0) and f.offset - 1 or f.offset
            if at + f.width > len then break end -- short forms: the fields that fit
            t:add(f.pf, ftvb(6 + at, f.width))
        end
        if p.flags:find("t", 1, true) then -- CAMERA_PASS: its camera bytes, maybe none
            add_data(t, ftvb(6 + p.len, len - p.len))
        end
    end
    t:add(F.checksum, ftvb(6 + len, 2))
    return name, t
end

local f_interface = Field.new("frame.interface_id")

-- Packet `pinfo.number` carries a chunk of direction `dir` of a `kind`
-- ("can" or "serial") stream. First pass: feed it and show the frames it
-- decided (what a single-pass tshark prints). Later passes: show the
-- frames whose last byte it carries.
local function dissect_chunk(tvb, pinfo, tree, kind, dir)
    local num = pinfo.number
    -- Field values exist only when the pass builds a protocol tree, which
    -- tshark -2's first pass does not without -R/-Y: there every capture
    -- interface is taken as interface 0.
    local ifid = f_interface()
    ifid = ifid and ifid.value or 0
    local frames = {}
    if not pinfo.visited then
        if decided[num] == nil and tvb:len() > 0 then
            local rate = kind == "can" and CAN_BYTES_PER_S or math.floor(tase.prefs.baud / 10)
            feed(kind .. ":" .. ifid .. ":" .. dir, tvb:raw(), num, pinfo.abs_ts, rate)
            ifaces[num] = ifid
        end
        frames = decided[num] or {}
    else
        settle()
        for _, fr in ipairs(ended[num] or {}) do frames[#frames + 1] = fr end
        for _, fr in ipairs(tails[num] or {}) do frames[#frames + 1] = fr end
        if ifaces[num] ~= nil and ifaces[num] ~= ifid then
            tree:add_proto_expert_info(E.merged)
        end
    end
    local names = {}
    for _, fr in ipairs(frames) do
        local t
        names[#names + 1], t = add_frame(tree, fr, dir)
        if fr.last ~= num then
            t:add(F.last_byte_in, fr.last):set_generated()
        elseif fr.decided == nil then
            t:add(F.decided_at_end, true):set_generated()
        elseif fr.decided ~= num then
            t:add(F.decided_in, fr.decided):set_generated()
        end
    end
    pinfo.cols.protocol = "TASE"
    if #names > 0 then
        pinfo.cols.info = dir .. " " .. table.concat(names, ", ")
    else
        pinfo.cols.info = string.format("%s %d datalink bytes (no complete packet)", dir, tvb:len())
    end
end

local function dissect_3ax(tvb, pinfo, tree, id)
    local move = id == ID_3AX_MOVE
    local name = move and "3AX_MOVE" or "3AX_STATUS"
    local t = tree:add(tase, tvb(), "TASE " .. name .. (move and " (gimbal to 3AX drive)" or
        " (3AX drive to gimbal)"))
    t:add(F.name, name):set_generated()
    t:add(F.size, tvb:len()):set_generated()
    pinfo.cols.protocol = "TASE"
    pinfo.cols.info = name
    if tvb:len() ~= 2 then
        t:add(F.error, "wrong length")
        t:add_proto_expert_info(E.wrong_length)
        return
    end
    if move then
        t:add(F.move_position, tvb(0, 1))
    else
        t:add(F.status_position, tvb(0, 1))
        t:add(F.status_speed, tvb(1, 1))
    end
end

-- A CAN FD frame on our IDs: not the datalink (classic CAN only, CAN.md),
-- as the library and `tase decode` skip it (its bytes went into the
-- stream: a packet around it was lost). More than 8 bytes is FD; an FD
-- frame of 8 or fewer is told by its flags field (Wireshark 4.0:
-- canfd.flags.brs), which exists only where the pass has a protocol tree:
-- tshark -2 needs -R frame for that in its first pass (as for several
-- capture interfaces, above).
local ok_fd, f_canfd_brs = pcall(Field.new, "canfd.flags.brs")

local function is_fd(tvb)
    return tvb:len() > 8 or (ok_fd and f_canfd_brs() ~= nil)
end

-- A remote frame (RTR) carries no data, whatever its DLC says: the
-- library and `tase decode` ignore it, and Wireshark hands it over with
-- DLC bytes, which went into the stream. Its flag, like the FD one, is
-- read from the protocol tree (tshark -2 needs -R frame for its first pass).
local ok_rtr, f_can_rtr = pcall(Field.new, "can.flags.rtr")

local function is_remote()
    if not ok_rtr then return false end
    local v = f_can_rtr()
    return v ~= nil and v.value == true
end

function tase.dissector(tvb, pinfo, tree)
    local id = pinfo.match_uint -- the CAN ID it was registered for
    if is_fd(tvb) or is_remote() then
        return 0
    end
    if id == ID_3AX_MOVE or id == ID_3AX_STATUS then
        dissect_3ax(tvb, pinfo, tree, id)
        return tvb:len()
    end
    local dir = CAN_DIRS[id]
    if dir == nil then return 0 end
    dissect_chunk(tvb, pinfo, tree, "can", dir)
    return tvb:len()
end

function tase_serial.dissector(tvb, pinfo, tree)
    local t = tree:add(tase_serial, tvb(), "TASE serial capture record")
    if tvb:len() < 1 then -- not even a direction byte
        t:add_proto_expert_info(E.no_bytes)
        pinfo.cols.protocol = "TASE"
        pinfo.cols.info = "empty record"
        return 0
    end
    t:add(F.serial_dir, tvb(0, 1))
    local dir = DIR_NAMES[tvb(0, 1):uint()]
    if dir == nil then
        t:add_proto_expert_info(E.bad_dir)
        pinfo.cols.protocol = "TASE"
        pinfo.cols.info = "bad direction byte"
        return tvb:len()
    end
    if tvb:len() < 2 then
        t:add_proto_expert_info(E.no_bytes)
        pinfo.cols.protocol = "TASE"
        pinfo.cols.info = "no bytes after the direction byte"
        return tvb:len()
    end
    t:add(F.serial_bytes, tvb(1))
    dissect_chunk(tvb(1):tvb(), pinfo, tree, "serial", dir)
    return tvb:len()
end

local can_ids = DissectorTable.get("can.extended_id")
for _, id in ipairs({0x10000000, 0x11000000, ID_3AX_MOVE, ID_3AX_STATUS}) do
    can_ids:add(id, tase)
end
DissectorTable.get("wtap_encap"):add(wtap_encaps.USER0, tase_serial)
