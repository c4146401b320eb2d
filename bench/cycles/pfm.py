"""PFM images for the Cycles race, in plain Python (no NumPy): read, compare, and write a PNG
preview. python3 pfm.py relrmse A.pfm REF.pfm | mean A.pfm | png A.pfm OUT.png"""
import array
import struct
import sys
import zlib


def read(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            raise SystemExit(f"pfm.py: {path}: not a colour PFM")
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = array.array("f")
        data.frombytes(f.read(width * height * 12))
    if scale > 0:
        data.byteswap()
    return width, height, data


def mean(data, channel=None):
    if channel is None:
        return sum(data) / len(data)
    values = data[channel::3]
    return sum(values) / len(values)


def rmse(a, b, channel=None):
    if channel is None:
        pairs = zip(a, b)
        n = len(a)
    else:
        pairs = zip(a[channel::3], b[channel::3])
        n = len(a) // 3
    return (sum((x - y) ** 2 for x, y in pairs) / n) ** 0.5


def relative_rmse(a, ref):
    """RMSE over all pixels and channels divided by the reference's mean over the same."""
    return rmse(a, ref) / mean(ref)


def to_png(path, width, height, data):
    def encode(v):
        v = min(max(v, 0.0), 1.0)
        v = 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
        return int(v * 255 + 0.5)

    rows = []
    for y in range(height - 1, -1, -1):  # PFM rows run bottom to top
        row = data[3 * width * y: 3 * width * (y + 1)]
        rows.append(b"\0" + bytes(encode(v) for v in row))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(b"".join(rows), 6)))
        f.write(chunk(b"IEND", b""))


if __name__ == "__main__":
    command = sys.argv[1]
    if command == "relrmse":
        _, _, a = read(sys.argv[2])
        _, _, r = read(sys.argv[3])
        print(f"{relative_rmse(a, r):.6g}")
    elif command == "mean":
        _, _, a = read(sys.argv[2])
        print(" ".join(f"{mean(a, c):.6g}" for c in range(3)), f"{mean(a):.6g}")
    elif command == "png":
        w, h, a = read(sys.argv[2])
        to_png(sys.argv[3], w, h, a)
    else:
        raise SystemExit(f"pfm.py: unknown command {command}")
