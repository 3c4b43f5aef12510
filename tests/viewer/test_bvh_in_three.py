"""An exported BVH read by an independent reader, three.js' BVHLoader (the one the issue measured), in Chromium."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.synthetic import generate_take
from stylemotion.io.bvh import read_bvh
from stylemotion.io.export import write_motion_bvh
from stylemotion.skeleton import CANONICAL_JOINTS
from stylemotion.viewer.motions import samples_to_motions
from stylemotion.viewer.page import write_viewer

pytestmark = pytest.mark.browser

#: World positions of every joint (End Sites left out) at the given frames, after BVHLoader parsed the file
#: and an AnimationMixer posed its skeleton at each frame's time.
THREE_FK = """([text, frames]) => {
  const result = new THREE.BVHLoader().parse(text);
  const bones = result.skeleton.bones.filter((b) => b.name !== "ENDSITE");
  const root = result.skeleton.bones[0];
  const mixer = new THREE.AnimationMixer(root);
  mixer.clipAction(result.clip).play();
  const step = result.clip.duration / (result.clip.tracks[0].times.length - 1);
  const v = new THREE.Vector3();
  const out = frames.map((f) => {
    mixer.setTime(f * step);
    root.updateMatrixWorld(true);
    return bones.map((b) => b.getWorldPosition(v).toArray());
  });
  return {names: bones.map((b) => b.name), positions: out};
}"""


def test_three_bvhloader_reads_the_export_as_written(browser, tmp_path):
    take = generate_take("run", "active", 1, duration_s=2.0)  # knees flexed far: the hardest angles
    path = tmp_path / "motion.bvh"
    write_motion_bvh(take.positions, path, take.fps)
    ours = read_bvh(path).global_positions()
    frames = list(range(0, ours.shape[0], 5))
    index = write_viewer(samples_to_motions(take.positions[None], [ours.shape[0]], take.fps, "run", 1),
                         tmp_path / "view")
    page = browser.new_page()
    page.goto(index.as_uri())
    page.wait_for_function("document.body.dataset.ready === '1'")
    three = page.evaluate(THREE_FK, [path.read_text(), frames])
    page.close()
    assert three["names"] == list(CANONICAL_JOINTS)
    seen = np.asarray(three["positions"])
    # the two readers agree (three works in float32): the file means one thing
    assert np.abs(seen - ours[frames]).max() < 1e-4
    # and every joint, hands and feet included, is where the motion had it
    error = np.linalg.norm(seen - take.positions[frames], axis=-1)
    print(f"three.js BVHLoader vs positions: max {error.max() * 100:.3f} cm at "
          f"{CANONICAL_JOINTS[int(error.max(0).argmax())]}")
    assert error.max() < 0.01
