"""Pictures small enough to keep in the repository: line drawings need a
few dozen colours, not 24 bits."""


def compact(path, colours=64):
    """The PNG with a palette of `colours` (line drawings need no more): a
    quarter of the bytes in the repository."""
    from PIL import Image

    Image.open(path).convert("RGB").quantize(colors=colours).save(path, optimize=True)


def compact_gif(path, colours=32):
    """The GIF's frames on one palette of `colours` taken from the first
    frame (every panel's colour is in it), without dithering."""
    from PIL import Image, ImageSequence

    gif = Image.open(path)
    duration = gif.info.get("duration", 80)
    frames = [f.convert("RGB") for f in ImageSequence.Iterator(gif)]
    palette = frames[0].quantize(colors=colours)
    frames = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=duration, loop=0, optimize=True)
