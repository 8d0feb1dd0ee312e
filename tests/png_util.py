# SPDX-License-Identifier: MIT
# PNG reading for the CLI tests (grey or RGB, 8 or 16 bits, no interlacing): png(path) gives
# (width, height, bits, channels, values) with the values row by row, channels interleaved.
import struct
import zlib


def png(path):
    b = open(path, "rb").read()
    assert b[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, hdr = 8, b"", None
    while pos < len(b):
        n, kind = struct.unpack(">I4s", b[pos:pos + 8])
        data = b[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", data)
        if kind == b"IDAT":
            idat += data
        pos += 12 + n
    w, h, bits, ctype = hdr[:4]
    ch = {0: 1, 2: 3}[ctype]
    bpp = ch * bits // 8
    raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
    for y in range(h):
        f = raw[y * (w * bpp + 1)]
        line = bytearray(raw[y * (w * bpp + 1) + 1:(y + 1) * (w * bpp + 1)])
        for i in range(len(line)):
            a = line[i - bpp] if i >= bpp else 0
            up, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + up) & 255
            elif f == 3:
                line[i] = (line[i] + (a + up) // 2) & 255
            elif f == 4:
                p = a + up - c
                pa, pb, pc = abs(p - a), abs(p - up), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else up if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    vals = [v for r in rows for v in (struct.unpack(">%dH" % (len(r) // 2), r) if bits == 16 else r)]
    return w, h, bits, ch, vals
