"""Test helper: write tracks as Tracker and Kinovea write them (our own content, shaped as the tools' files).

The shapes follow the tools' sources: Tracker's XMLControl of a TrackerPanel (VideoClip,
StepperClipControl, ImageCoordSystem, PointMass framedata indexed by frame number; the
ExportDataDialog's table) and Kinovea's MetadataSerializer (KinoveaVideoAnalysis 2.1, Tracks
with TrackPoint "x;y;t;r"; ExporterCSVTrajectory's quoted CSV). ``tracks`` below is
{tool track name: (frames, x_px, y_px)} in image pixels, y downward.
"""

from __future__ import annotations

import csv
import math
import zipfile
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from ballbat.tracks.data import POINTS

#: ballbat point -> the tool's track name, as a lab might name them.
TOOL_NAMES = {"ball": "ball", "bat_tip": "tip", "dot_a": "A", "dot_b": "B"}
TRACKER = "org.opensourcephysics.cabrillo.tracker"
MEDIA = "org.opensourcephysics.media.core"


def read_long_csv(path: Path) -> dict[tuple[str, str], dict[str, tuple]]:
    """A long tracks CSV -> {(impact_id, camera): {tool track name: (frames, x, y)}}."""
    from ballbat.pipeline.checked import read_sealed_csv

    text = Path(path).read_text()
    if "\n# ballbat table: " in text:  # ballbat import-tracks ends its CSV in the check line
        text = read_sealed_csv(path)
    rows: dict[tuple[str, str], dict[str, list]] = {}
    for r in csv.DictReader(text.splitlines()):
        key = (r["impact_id"], r["camera"])
        name = TOOL_NAMES[r["point"]]
        d = rows.setdefault(key, {}).setdefault(name, ([], [], []))
        d[0].append(int(r["frame"]))
        d[1].append(float(r["x_px"]))
        d[2].append(float(r["y_px"]))
    return {k: {n: tuple(np.array(a) for a in v) for n, v in t.items()} for k, t in rows.items()}


def _jd(v: float) -> str:
    """A double as Java's Double.toString writes it (for the values used here)."""
    return repr(float(v))


def _object(name: str, cls: str, inner: list[str], ind: str) -> list[str]:
    """A property of type object holding an object of class ``cls`` with the lines ``inner``."""
    return [
        f'{ind}<property name="{name}" type="object">',
        f'{ind}<object class="{cls}">',
        *inner,
        f"{ind}</object>",
        f"{ind}</property>",
    ]


def _prop(name: str, typ: str, value: str, ind: str) -> str:
    return f'{ind}<property name="{name}" type="{typ}">{value}</property>'


def trk_text(
    tracks: dict,
    fps: float,
    m_per_px: float,
    *,
    unit: str = "m",
    angle_deg: float = 0.0,
    origin=(600.0, 400.0),
    video: str = "clip.mp4",
    extra_mark: int | None = None,
    step: int = 1,
) -> str:
    """A Tracker project (.trk) holding ``tracks`` as point masses (image pixels); clip step size ``step``."""
    frames = np.concatenate([t[0] for t in tracks.values()])
    start = int(frames.min())
    count = (int(frames.max()) - start) // step + 4
    to_m = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}[unit]
    scale = to_m / m_per_px  # px per unit
    i1, i2, i3, i4 = "    ", "        ", "            ", "                "
    out = ['<?xml version="1.0" encoding="UTF-8"?>', f'<object class="{TRACKER}.TrackerPanel" version="6.1.5">']
    out += [
        _prop("semantic_version", "string", "6.1.5", i1),
        _prop("width", "int", "1200", i1),
        _prop("height", "int", "800", i1),
        _prop("magnification", "double", "1.0", i1),
        _prop("center_x", "int", "600", i1),
        _prop("center_y", "int", "400", i1),
    ]
    video_object = _object(
        "video",
        "org.opensourcephysics.media.mov.MovieVideo",
        [
            _prop("path", "string", escape(video), i3),
            f'{i3}<property name="filters" type="collection" class="java.util.ArrayList" />',
        ],
        i2,
    )
    out += _object(
        "videoclip",
        f"{MEDIA}.VideoClip",
        [
            *video_object,
            _prop("video_framecount", "int", str(start + count + 20), i2),
            _prop("startframe", "int", str(start), i2),
            _prop("stepsize", "int", str(step), i2),
            _prop("stepcount", "int", str(count), i2),
            _prop("starttime", "double", "0.0", i2),
            _prop("readout", "string", "frame", i2),
            _prop("playallsteps", "boolean", "true", i2),
        ],
        i1,
    )
    out += _object(
        "clipcontrol",
        f"{MEDIA}.StepperClipControl",
        [
            _prop("rate", "double", "1.0", i2),
            _prop("delta_t", "double", _jd(1000.0 / fps), i2),
            _prop("frame", "int", str(start), i2),
        ],
        i1,
    )
    frame_data = _object(
        "[0]",
        f"{MEDIA}.ImageCoordSystem$FrameData",
        [
            _prop("xorigin", "double", _jd(origin[0]), i4),
            _prop("yorigin", "double", _jd(origin[1]), i4),
            _prop("angle", "double", _jd(angle_deg), i4),
            _prop("xscale", "double", _jd(scale), i4),
            _prop("yscale", "double", _jd(scale), i4),
        ],
        i3,
    )
    out += _object(
        "coords",
        f"{MEDIA}.ImageCoordSystem",
        [
            _prop("fixedorigin", "boolean", "true", i2),
            _prop("fixedangle", "boolean", "true", i2),
            _prop("fixedscale", "boolean", "true", i2),
            _prop("locked", "boolean", "false", i2),
            f'{i2}<property name="framedata" type="array" class="[L{MEDIA}.ImageCoordSystem$FrameData;">',
            *frame_data,
            f"{i2}</property>",
        ],
        i1,
    )
    out += [
        _prop("length_unit", "string", unit, i1),
        _prop("mass_unit", "string", "kg", i1),
        _prop("units_visible", "boolean", "true", i1),
        f'{i1}<property name="tracks" type="collection" class="java.util.ArrayList">',
        f'{i2}<property name="item" type="object">',
        f'{i2}<object class="{TRACKER}.CoordAxes">',
        _prop("name", "string", "axes", i3),
        _prop("visible", "boolean", "false", i3),
        f"{i2}</object>",
        f"{i2}</property>",
    ]
    a = math.radians(angle_deg)
    for k, (name, (fr, x, y)) in enumerate(tracks.items()):
        if angle_deg:  # the lab's axes are turned: the image shows the scene turned the other way
            u, v = x - origin[0], -(y - origin[1])
            x, y = origin[0] + math.cos(a) * u - math.sin(a) * v, origin[1] - (math.sin(a) * u + math.cos(a) * v)
        out += [
            f'{i2}<property name="item" type="object">',
            f'{i2}<object class="{TRACKER}.PointMass">',
            _prop("name", "string", escape(name), i3),
            _prop("description", "string", "", i3),
            f'{i3}<property name="color" type="object">',
            f'{i3}<object class="java.awt.Color">',
            _prop("red", "int", str(255 - 60 * k), i4),
            _prop("green", "int", "0", i4),
            _prop("blue", "int", str(60 * k), i4),
            _prop("alpha", "int", "255", i4),
            f"{i3}</object>",
            f"{i3}</property>",
            _prop("footprint", "string", "CircleFootprint.Circle#5 outline", i3),
            _prop("visible", "boolean", "true", i3),
            _prop("trail", "boolean", "true", i3),
            _prop("locked", "boolean", "false", i3),
            _prop("mass", "double", "1.0", i3),
            f'{i3}<property name="framedata" type="array" class="[L{TRACKER}.PointMass$FrameData;">',
        ]
        marks = list(zip(fr, x, y, strict=True))
        if extra_mark is not None and k == 0:
            marks.append((extra_mark, 1.0, 2.0))
        for f, xx, yy in marks:
            out += [
                f'{i4}<property name="[{int(f)}]" type="object">',
                f'{i4}<object class="{TRACKER}.PointMass$FrameData">',
                _prop("x", "double", _jd(xx), i4 + "    "),
                _prop("y", "double", _jd(yy), i4 + "    "),
                f"{i4}</object>",
                f"{i4}</property>",
            ]
        keys = ",".join(str(int(f)) for f in fr)
        out += [
            f"{i3}</property>",
            f'{i3}<property name="keyFrames" type="array" class="[I">{{{keys}}}</property>',
            f"{i2}</object>",
            f"{i2}</property>",
        ]
    out += [f"{i1}</property>", "</object>", ""]
    return "\n".join(out)


def write_trz(path: Path, trk: str, name: str = "project.trk") -> None:
    """A Tracker archive: the project, its HTML description and (here) no video."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr(name, trk)
        z.writestr("html/description.html", "<html><body>ballbat test project</body></html>")


def kva_text(
    tracks: dict,
    fps: float,
    m_per_px: float | None,
    *,
    per_frame: int = 512,
    first: int = 0,
    video_fps: float = 30.0,
    mirror: bool = False,
) -> str:
    """A Kinovea annotation file (.kva, format 2.1) holding ``tracks`` (image pixels, timestamps)."""
    frames = np.concatenate([t[0] for t in tracks.values()])
    out = [
        '<?xml version="1.0" encoding="utf-8"?>',
        "<KinoveaVideoAnalysis>",
        "  <FormatVersion>2.1</FormatVersion>",
        "  <Producer>Kinovea.2023.1.2</Producer>",
        "  <OriginalFilename>clip</OriginalFilename>",
        "  <FullPath>C:\\lab\\clip.avi</FullPath>",
        "  <ByteLength>104857600</ByteLength>",
        "  <ImageSize>1200;800</ImageSize>",
        "  <Aspect>Auto</Aspect>",
        "  <Rotation>Rotate0</Rotation>",
        f"  <Mirror>{str(mirror).lower()}</Mirror>",
        "  <Demosaicing>None</Demosaicing>",
        "  <Deinterlacing>false</Deinterlacing>",
        "  <StabilizationTrack>00000000-0000-0000-0000-000000000000</StabilizationTrack>",
        "  <BackgroundColor>255;255;255;255</BackgroundColor>",
        f"  <AverageTimeStampsPerFrame>{per_frame}</AverageTimeStampsPerFrame>",
        f"  <CaptureFramerate>{fps:g}</CaptureFramerate>",
        f"  <VideoFramerate>{video_fps:g}</VideoFramerate>",
        f"  <FirstTimeStamp>{first}</FirstTimeStamp>",
        f"  <SelectionStart>{first}</SelectionStart>",
        f"  <SelectionEnd>{first + per_frame * (int(frames.max()) + 10)}</SelectionEnd>",
        f"  <TimeOrigin>{first}</TimeOrigin>",
    ]
    if m_per_px is not None:  # a 1 m line drawn along the image's x
        px = 1.0 / m_per_px
        out += [
            "  <Calibration>",
            "    <CalibrationLine>",
            "      <Length>100</Length>",
            "      <Segment>",
            "        <A>100;700</A>",
            f"        <B>{np.float32(100 + px)};700</B>",
            "      </Segment>",
            "      <Origin>0;0</Origin>",
            "      <Offset>0;0</Offset>",
            "      <Axis>LineHorizontal</Axis>",
            "    </CalibrationLine>",
            "    <CalibrationDrawingId>3f2b8c1e-0000-4000-8000-000000000001</CalibrationDrawingId>",
            '    <Unit Abbreviation="cm">Centimeters</Unit>',
            "  </Calibration>",
        ]
    out.append("  <Tracks>")
    for k, (name, (fr, x, y)) in enumerate(tracks.items()):
        t = first + per_frame * np.asarray(fr, dtype=np.int64)
        out += [
            f'    <Track id="7c1d0a52-0000-4000-8000-00000000000{k}" name="{escape(name)}">',
            f"      <TimePosition>{t[0]}</TimePosition>",
            "      <IsVisible>true</IsVisible>",
            "      <Visible>-1</Visible>",
            "      <Invisible>-1</Invisible>",
            "      <ExtraData>None</ExtraData>",
            "      <TrackerParameters>",
            "        <TrackingAlgorithm>Circle</TrackingAlgorithm>",
            "      </TrackerParameters>",
            f'      <TrackPointList Count="{len(fr)}">',
        ]
        out += [
            f"        <TrackPoint>{float(xx)!r};{float(yy)!r};{int(tt)};0</TrackPoint>"
            for xx, yy, tt in zip(x, y, t, strict=True)
        ]
        out += [
            "      </TrackPointList>",
            f'      <MainLabel Text="{escape(name)}">',
            "        <SpacePosition>10;10</SpacePosition>",
            f"        <TimePosition>{t[0]}</TimePosition>",
            "      </MainLabel>",
            "      <SeeFuture>true</SeeFuture>",
            "      <ShowTrackLabel>false</ShowTrackLabel>",
            "      <DrawingStyle>",
            '        <Color Key="color">',
            "          <Value>255;255;0;0</Value>",
            "        </Color>",
            "      </DrawingStyle>",
            "    </Track>",
        ]
    out += ["  </Tracks>", "</KinoveaVideoAnalysis>", ""]
    return "\n".join(out)


def kinovea_csv_text(tracks: dict, fps: float, m_per_px: float, *, origin=(100.0, 700.0)) -> str:
    """Kinovea's trajectory CSV export in world space: time in ms, x and y in cm, y up."""
    per_cm = m_per_px * 100.0
    table: dict[int, dict[str, tuple[float, float]]] = {}
    for name, (fr, x, y) in tracks.items():
        for f, xx, yy in zip(fr, x, y, strict=True):
            table.setdefault(int(f), {})[name] = ((xx - origin[0]) * per_cm, (origin[1] - yy) * per_cm)
    f0 = min(table)
    lines = [",".join(['"Time"'] + [f'"{n}/0/X","{n}/0/Y"' for n in tracks])]
    for f in sorted(table):
        cells = [f'"{np.float32((f - f0) * 1000.0 / fps)!s}"']
        for n in tracks:
            v = table[f].get(n)
            cells += [f'"{np.float32(v[0])!s}"', f'"{np.float32(v[1])!s}"'] if v else ["", ""]
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def _java_sci(v: float) -> str:
    """Java's DecimalFormat("0.000000E0"), Tracker's full-precision export pattern."""
    mant, exp = f"{v:.6E}".split("E")
    return f"{mant}E{int(exp)}"


def tracker_table_text(tracks: dict, fps: float, m_per_px: float, *, origin=(600.0, 400.0), delim="\t") -> str:
    """Tracker's exported data table: track names, t x y columns per track, t in s, metres, y up."""
    table: dict[int, dict[str, tuple[float, float]]] = {}
    for name, (fr, x, y) in tracks.items():
        for f, xx, yy in zip(fr, x, y, strict=True):
            table.setdefault(int(f), {})[name] = ((xx - origin[0]) * m_per_px, (origin[1] - yy) * m_per_px)
    f0 = min(table)
    lines = [
        "#multi:",
        delim + "".join(f"{n}{delim}{delim}" for n in tracks),
        "t" + delim + "".join(f"x{delim}y{delim}" for _ in tracks),
    ]
    for f in range(f0, max(table) + 1):
        row = [_java_sci((f - f0) / fps)]
        for n in tracks:
            v = table.get(f, {}).get(n)
            row += [_java_sci(v[0]), _java_sci(v[1])] if v else ["", ""]
        lines.append(delim.join(row))
    return "\n".join(lines) + "\n"


def write_lab_folder(folder: Path, long_csv: Path, fmt: str, cameras: dict) -> Path:
    """Write every impact and camera of a long tracks CSV as one file of format ``fmt`` in ``folder``.

    ``cameras``: {camera: {fps, m_per_px}}. Formats: trk, trz, kva, kinovea_csv, tracker_table.
    """
    folder.mkdir(parents=True, exist_ok=True)
    for (iid, cam), tracks in read_long_csv(long_csv).items():
        order = [TOOL_NAMES[p] for p in POINTS[cam]]
        tracks = {n: tracks[n] for n in order}
        fps, mpp = cameras[cam]["fps"], cameras[cam]["m_per_px"]
        stem = f"{iid}_{cam}"
        if fmt == "trk":
            (folder / f"{stem}.trk").write_text(trk_text(tracks, fps, mpp, video=f"{stem}.mp4"))
        elif fmt == "trz":
            write_trz(folder / f"{stem}.trz", trk_text(tracks, fps, mpp, video=f"{stem}.mp4"), f"{stem}.trk")
        elif fmt == "kva":
            (folder / f"{stem}.kva").write_text(kva_text(tracks, fps, mpp))
        elif fmt == "kinovea_csv":
            (folder / f"{stem}.csv").write_text(kinovea_csv_text(tracks, fps, mpp))
        elif fmt == "tracker_table":
            (folder / f"{stem}.txt").write_text(tracker_table_text(tracks, fps, mpp))
        else:
            raise ValueError(fmt)
    return folder
