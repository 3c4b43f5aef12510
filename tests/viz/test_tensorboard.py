"""TensorBoard pictures: sample images after training and an evaluation report's figures and numbers."""

from __future__ import annotations

import numpy as np
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator
from torch.utils.tensorboard import SummaryWriter
from viewer_fixtures import synthetic_samples, tiny_results

from stylemotion.evaluation.report import write_report
from stylemotion.viz.animation import render_samples
from stylemotion.viz.tensorboard import log_sample_images


def _events(folder) -> EventAccumulator:
    acc = EventAccumulator(str(folder), size_guidance={"images": 0, "tensors": 0})
    acc.Reload()
    return acc


def test_sample_images(tmp_path):
    samples = synthetic_samples()
    gif, png = render_samples(samples, tmp_path / "samples", count=2)
    writer = SummaryWriter(str(tmp_path / "tb"))
    log_sample_images(writer, gif, png, step=7)
    writer.close()
    acc = _events(tmp_path / "tb")
    assert set(acc.Tags()["images"]) == {"samples/last_frames", "samples/animation"}
    sheet = acc.Images("samples/last_frames")[0]
    assert sheet.step == 7 and sheet.width > 600 and sheet.height > 200
    frame_width = np.asarray(__import__("PIL.Image").Image.open(gif).size)[0]
    assert acc.Images("samples/animation")[0].width >= 4 * frame_width  # a grid of 8 GIF frames


def test_report_figures_and_numbers(tmp_path):
    results = tiny_results(columns_on_diagonal=("neutral",))
    out = write_report(results, tmp_path / "report")
    acc = _events(out / "tensorboard")
    assert acc.Tags()["images"] == ["report/table_5_1_walk_leftStance"]
    image = acc.Images("report/table_5_1_walk_leftStance")[0]
    assert image.width > 300
    scalars = {t: acc.Scalars(t)[0].value for t in acc.Tags()["scalars"]}
    assert scalars == {"table_5_1/walk_leftStance/diagonal_rows": 2.0,
                       "table_5_1/walk_leftStance/diagonal_columns": 1.0}
    from tensorboard.plugins.hparams import plugin_data_pb2

    start = plugin_data_pb2.HParamsPluginData.FromString(
        acc.PluginTagToContent("hparams")["_hparams_/session_start_info"]).session_start_info
    assert start.hparams["data"].string_value == "synthetic" and start.hparams["seed"].number_value == 3
