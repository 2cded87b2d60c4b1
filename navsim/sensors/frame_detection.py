"""How the image-fidelity star sensor finds the stars of a full frame: one strategy object per detector, chosen by
``star_sensor.image.detection`` (:data:`FULL_FRAME_DETECTORS`); each answers ``find(image, model, trail)`` with the
frame's :class:`startrack.image.detection.Detections`, ``model`` the frame's
:class:`~startrack.image.render.SensorModel` and ``trail`` a function giving the trail (Δu, Δv) [px] the predicted
attitude and rate draw at the boresight over the exposure (called only by a detector that uses it). The readout
windows of a tracking frame keep 004's threshold (:func:`startrack.detect_windows`)."""

from dataclasses import dataclass

from startrack import detect, detect_trailed


@dataclass(frozen=True)
class ThresholdDetection:
    """004's detector: the pixels above V_th = b + a σ_n (``sigmas`` = a), grouped and centroided
    (:func:`startrack.detect`)."""

    sigmas: float

    def find(self, image, model, trail):
        return detect(image, background=model.background_dn, sigma_n=model.noise_dn, a=self.sigmas,
                      saturation_dn=model.saturation_dn)


@dataclass(frozen=True)
class MatchedDetection:
    """The matched filter of the PSF drawn along the predicted trail, at its stated false-detection rate
    (:func:`startrack.detect_trailed`, issue 53): one template for the whole frame, the boresight's (a roll about
    the boresight lengthens the trails off the centre, which it does not follow)."""

    def find(self, image, model, trail):
        return detect_trailed(image, model.psf_sigma_px, trail(), background=model.background_dn,
                              sigma_n=model.noise_dn, saturation_dn=model.saturation_dn, fit=False)


#: The full-frame detectors by their scenario name (``star_sensor.image.detection``), each built from the sensor's
#: checked ``image`` table.
FULL_FRAME_DETECTORS = {"threshold": lambda image: ThresholdDetection(image["detection_sigmas"]),
                        "matched": lambda image: MatchedDetection()}
