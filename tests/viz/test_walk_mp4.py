"""MP4 export through the ffmpeg binary of imageio-ffmpeg: the file decodes, with the expected frames."""

from __future__ import annotations

import imageio_ffmpeg
import numpy as np

from stylemotion.datasets.synthetic import generate_take
from stylemotion.viz.walk import mp4_available, save_walk_animation


def test_walk_mp4_decodes(tmp_path):
    assert mp4_available()
    take = generate_take("walk", "normal", 0, duration_s=1.0)
    root = take.positions[:, 0][:, [0, 2]]
    out = save_walk_animation(take.positions, take.fps, root, tmp_path / "walk.mp4", keyframes=[10, 20],
                              title="mp4 test", display_fps=25, dpi=40)
    assert out.is_file() and [p.name for p in tmp_path.iterdir()] == ["walk.mp4"]  # no temporary left
    assert out.read_bytes()[4:8] == b"ftyp"  # an ISO-BMFF (MP4) file
    reader = imageio_ffmpeg.read_frames(str(out))  # decoded by ffmpeg, independently of the writer
    meta = reader.__next__()
    width, height = meta["size"]
    frames = [np.frombuffer(f, dtype=np.uint8).reshape(height, width, 3) for f in reader]
    expected = int(np.ceil((take.positions.shape[0] - 1) / take.fps * 25)) + 1
    assert len(frames) == expected and meta["codec"] == "h264"
    assert frames[0].std() > 1.0  # not blank
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).max() > 50  # the figure moved
