"""fxtext.py - 16.16 fixed-point values as exact decimal text: what build/render's --at and
--angle (tools/bspc/fxtext.c) parse back to the same raw value."""


def fx_text(raw):
    """The exact decimal of a raw 16.16 value (1/65536 = 0.0000152587890625)."""
    sign, raw = ("-" if raw < 0 else ""), abs(raw)
    whole, frac = raw >> 16, raw & 0xFFFF
    return f"{sign}{whole}" + (f".{frac * 152587890625:016d}".rstrip("0") if frac else "")
