"""Video in: synthetic high-speed clips, the files labs have, and tracking the points in them (docs/video.md).

* :mod:`.scene` -- the truth of a rendered clip (from :mod:`ballbat.tracks.render`).
* :mod:`.render` -- frames drawn from it (shading, blur, lighting, noise, bit depth).
* :mod:`.io` -- writers and streamed readers of TIFF stacks, FFV1 and H.264 video.
* :mod:`.track` -- the ball, its dots and the bat tip found in each frame, linked, as long tracks.
"""
