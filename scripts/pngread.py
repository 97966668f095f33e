"""pngread.py - PNG images for the scripts and benches that compare them
without a library: read_png (8/16-bit grey, grey+alpha, RGB, RGBA or palette,
not interlaced) and mad4 (the sRGB mean absolute difference after a 4x4 box
downsample, issue bounds and cross-checks use it). Import with scripts/ on
sys.path."""
import struct
import zlib


def read_png(path):
    """8/16-bit grey, grey+alpha, RGB, RGBA or palette PNG -> (w, h, rows of [r,g,b] in 0..1)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG: " + path)
    pos, idat, plte = 8, b"", None
    while pos < len(data):
        n, = struct.unpack(">I", data[pos:pos + 4])
        typ, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if typ == b"IHDR":
            w, h, depth, ct, _, _, interlace = struct.unpack(">IIBBBBB", body)
        elif typ == b"IDAT":
            idat += body
        elif typ == b"PLTE":
            plte = body
    if interlace:
        raise ValueError("interlaced PNG not supported: " + path)
    ch = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ct]
    bpp = max(1, ch * depth // 8)
    stride = (w * ch * depth + 7) // 8
    raw = zlib.decompress(idat)
    rows, prev, p = [], bytearray(stride), 0
    for _ in range(h):
        f, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
        p += 1 + stride
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else (b if pb <= pc else c))) & 255
        prev = line
        row = []
        for x in range(w):
            if ct == 3:
                k = line[x]
                px = [plte[3 * k] / 255, plte[3 * k + 1] / 255, plte[3 * k + 2] / 255]
            elif depth == 16:
                px = [struct.unpack(">H", line[(x * ch + k) * 2:(x * ch + k) * 2 + 2])[0] / 65535 for k in range(ch)]
            else:
                px = [line[x * ch + k] / 255 for k in range(ch)]
            if ct in (0, 4):
                px = [px[0]] * 3
            row.append(px[:3])
        rows.append(row)
    return w, h, rows


def mad4(a, b):
    """Mean |a - b| over the channels after a 4x4 box downsample."""
    wa, ha, A = a
    wb, hb, B = b
    if (wa, ha) != (wb, hb):
        return 1.0
    s, n = 0.0, 0
    for y in range(0, ha - ha % 4, 4):
        for x in range(0, wa - wa % 4, 4):
            for k in range(3):
                sa = sum(A[y + j][x + i][k] for j in range(4) for i in range(4))
                sb = sum(B[y + j][x + i][k] for j in range(4) for i in range(4))
                s += abs(sa - sb) / 16.0
                n += 1
    return s / n if n else 1.0
