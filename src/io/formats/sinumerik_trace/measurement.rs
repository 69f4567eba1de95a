//! What a measuring-function file holds, typed: the test's settings, the excitation,
//! the axis as the drive describes it, and each measured signal with its time series
//! (one per direction), its autospectrum and its cross spectra — read from the
//! document by the members' names (module docs of [`super`]).

use roxmltree::Node;

use super::document::Doc;
use crate::io::formats::FormatError;

/// One measuring-function file.
#[derive(Clone, Debug, PartialEq)]
pub struct Measurement {
    /// The root element's tag (`ResponseTestCustom`).
    pub root: String,
    /// The SAT library's version (the root's `ver`).
    pub version: String,
    /// `m_dProcessUpdateTime`, s: the sample time of the series.
    pub sample_time_s: f64,
    /// `m_eControlLoopType`: which control loop was measured (2: the speed loop).
    pub loop_type: u32,
    /// `m_eWaveformType` (4: PRBS).
    pub waveform: u32,
    /// `m_eInjectionPoint_rtc` (3: the speed setpoint, in the shared file).
    pub injection_point: u32,
    /// `Date` (YYYYMMDD) and `Time` (hhmmss.s) of `m_timeStampMeas`, as written.
    pub timestamp: Option<(String, String)>,
    /// `m_strPlatformID` (the machine's name).
    pub platform: Option<String>,
    pub excitation: Excitation,
    /// `m_listpResponseTestConditions`: one per direction.
    pub conditions: Vec<TestCondition>,
    /// `m_MeasurementSignalNodeList`.
    pub signals: Vec<Signal>,
    /// `m_listPrimaryFreqRespSigNodeData`: the unique instance ids of the primary
    /// response's input and output signals.
    pub primary: Option<(i64, i64)>,
}

/// `m_ExcitationSourceList`'s (first) source.
#[derive(Clone, Debug, PartialEq)]
pub struct Excitation {
    /// `m_eControlLoop`.
    pub control_loop: u32,
    /// `m_uPrbsOrder`: the PRBS repeats every 2^order − 1 samples.
    pub prbs_order: Option<u32>,
    /// `m_bClosedLoop`: measured with the loop closed.
    pub closed_loop: bool,
    pub axis: AxisFacts,
    /// `m_listpExcitationSourceConditions`: offset and amplitude per direction.
    pub levels: Vec<Level>,
}

/// The axis as the drive describes it.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisFacts {
    pub rotary: bool,
    pub direct_drive: bool,
    pub linear_motor: bool,
    /// `m_dMotorToAxisRatio`: motor rad per axis unit (rad/m on a linear axis).
    pub motor_to_axis_ratio: f64,
    /// `m_dMotorForceConstant`: N·m/A (N/A for a linear motor).
    pub torque_constant: f64,
}

/// An excitation's offset and amplitude for one role (direction).
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub role: u32,
    /// `m_dOffsetAmplitude`, in the loop's SI unit (rad/s of the motor for the speed
    /// loop).
    pub offset: f64,
    /// `m_dExcitationAmplitude`, the same unit.
    pub amplitude: f64,
}

/// A measurement's settings for one role (direction).
#[derive(Clone, Debug, PartialEq)]
pub struct TestCondition {
    pub role: u32,
    pub settling_time_s: f64,
    pub measurement_time_s: f64,
    /// `m_uNumberOfAverages` as set.
    pub averages: u32,
    pub sampling_interval_s: f64,
    pub bandwidth_hz: f64,
}

/// One measured signal (`PlatformSignalNode`).
#[derive(Clone, Debug, PartialEq)]
pub struct Signal {
    /// `m_uNodeId`: the drive's signal number.
    pub node: u32,
    /// `m_iUniqueInstanceId`: how the primary response names it.
    pub instance: i64,
    /// `m_eSignalUnits` (0 in the shared file: the loop's SI unit).
    pub units: u32,
    /// `m_TimeSeriesList`: one per direction, in the file's order.
    pub series: Vec<Series>,
    /// `m_autospectrumInfo`.
    pub autospectrum: Option<Spectrum>,
    /// `m_crossSpecInfoList`: with the signal `other` of each.
    pub cross: Vec<Spectrum>,
    /// The text offset of the element, for errors found later.
    pub at: usize,
}

/// One time series.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub values: Vec<f64>,
    /// `m_TimeVector.start` and `.end`, s.
    pub start_s: f64,
    pub end_s: f64,
}

/// An averaged spectrum (`SigNodeCrossSpectrumInfo`).
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    /// `m_uSecondId`/`m_uSignodeId`: the other signal's node (0 in an autospectrum).
    pub other: u32,
    /// `m_uNumSpectraInAvg`.
    pub averaged: u32,
    pub re: Vec<f64>,
    pub im: Vec<f64>,
    /// `m_FrequencyVector` as the file states it, Hz.
    pub frequency_hz: Vec<f64>,
}

impl Measurement {
    /// Reads the measurement from the document's root.
    pub(super) fn of(doc: &Doc, root: Node) -> Result<Measurement, FormatError> {
        let excitation = doc.list(root, "m_ExcitationSourceList")?;
        let Some(&source) = excitation.first() else {
            return Err(doc.fail(root, "m_ExcitationSourceList holds no excitation source"));
        };
        Ok(Measurement {
            root: root.tag_name().name().to_string(),
            version: root.attribute("ver").unwrap_or("").to_string(),
            sample_time_s: positive(doc, root, "m_dProcessUpdateTime")?,
            loop_type: doc.unsigned(root, "m_eControlLoopType")?,
            waveform: doc.unsigned(root, "m_eWaveformType")?,
            injection_point: doc.unsigned(root, "m_eInjectionPoint_rtc")?,
            timestamp: timestamp(doc, root),
            platform: platform(doc, root),
            excitation: Excitation::of(doc, source)?,
            conditions: doc
                .list(root, "m_listpResponseTestConditions")?
                .into_iter()
                .map(|c| TestCondition::of(doc, c))
                .collect::<Result<_, _>>()?,
            signals: doc
                .list(root, "m_MeasurementSignalNodeList")?
                .into_iter()
                .map(|s| Signal::of(doc, s))
                .collect::<Result<_, _>>()?,
            primary: primary(doc, root)?,
        })
    }

    /// The signal whose unique instance id is `instance`.
    pub fn signal(&self, instance: i64) -> Option<&Signal> {
        self.signals.iter().find(|s| s.instance == instance)
    }
}

/// A member that must be a positive time or frequency.
fn positive(doc: &Doc, node: Node, name: &str) -> Result<f64, FormatError> {
    let v = doc.float(node, name)?;
    if v > 0.0 {
        Ok(v)
    } else {
        let member = doc.need(node, "float", name)?;
        Err(doc.fail(member, format!("{v}: it must be positive")))
    }
}

fn timestamp(doc: &Doc, root: Node) -> Option<(String, String)> {
    let stamp = doc.child(root, "SatTimeStamp", "m_timeStampMeas")?;
    let text = |tag, name| Some(doc.child(stamp, tag, name)?.text()?.trim().to_string());
    Some((text("unsigned_int", "Date")?, text("float", "Time")?))
}

fn platform(doc: &Doc, root: Node) -> Option<String> {
    let details = doc.child(root, "SatPlatformDetails", "m_platformDetailsMeas")?;
    Some(
        doc.child(details, "string", "m_strPlatformID")?
            .text()?
            .trim()
            .to_string(),
    )
}

/// The first primary response's (input, output) instance ids, if the file names one.
fn primary(doc: &Doc, root: Node) -> Result<Option<(i64, i64)>, FormatError> {
    if doc
        .child(root, "LinkedList", "m_listPrimaryFreqRespSigNodeData")
        .is_none()
    {
        return Ok(None);
    }
    let list = doc.list(root, "m_listPrimaryFreqRespSigNodeData")?;
    let Some(&first) = list.first() else {
        return Ok(None);
    };
    Ok(Some((
        doc.value(first, "integer", "m_iInputSigNodeUniqueInstanceID")?,
        doc.value(first, "integer", "m_iOutputSigNodeUniqueInstanceID")?,
    )))
}

impl Excitation {
    fn of(doc: &Doc, source: Node) -> Result<Excitation, FormatError> {
        Ok(Excitation {
            control_loop: doc.unsigned(source, "m_eControlLoop")?,
            prbs_order: doc
                .child(source, "unsigned_int", "m_uPrbsOrder")
                .map(|_| doc.unsigned(source, "m_uPrbsOrder"))
                .transpose()?,
            closed_loop: doc.boolean(source, "m_bClosedLoop")?,
            axis: AxisFacts {
                rotary: doc.boolean(source, "m_bIsRotaryAxis")?,
                direct_drive: doc.boolean(source, "m_bIsDirectDrive")?,
                linear_motor: doc.boolean(source, "m_bIsLinearMotor")?,
                motor_to_axis_ratio: doc.float(source, "m_dMotorToAxisRatio")?,
                torque_constant: doc.float(source, "m_dMotorForceConstant")?,
            },
            levels: doc
                .list(source, "m_listpExcitationSourceConditions")?
                .into_iter()
                .map(|c| {
                    Ok(Level {
                        role: doc.unsigned(c, "m_eMyRole")?,
                        offset: doc.float(c, "m_dOffsetAmplitude")?,
                        amplitude: doc.float(c, "m_dExcitationAmplitude")?,
                    })
                })
                .collect::<Result<_, FormatError>>()?,
        })
    }
}

impl TestCondition {
    fn of(doc: &Doc, c: Node) -> Result<TestCondition, FormatError> {
        Ok(TestCondition {
            role: doc.unsigned(c, "m_eMyRole")?,
            settling_time_s: doc.float(c, "m_dSettlingTime")?,
            measurement_time_s: doc.float(c, "m_dMeasurementTime")?,
            averages: doc.unsigned(c, "m_uNumberOfAverages")?,
            sampling_interval_s: positive(doc, c, "m_dSamplingInterval")?,
            bandwidth_hz: positive(doc, c, "m_dBandwidth")?,
        })
    }
}

impl Signal {
    fn of(doc: &Doc, node: Node) -> Result<Signal, FormatError> {
        let autospectrum = doc
            .child(node, "SigNodeCrossSpectrumInfo", "m_autospectrumInfo")
            .map(|s| spectrum(doc, s, "m_uSecondId"))
            .transpose()?;
        Ok(Signal {
            node: doc.unsigned(node, "m_uNodeId")?,
            instance: doc.value(node, "integer", "m_iUniqueInstanceId")?,
            units: doc.unsigned(node, "m_eSignalUnits")?,
            series: doc
                .list(node, "m_TimeSeriesList")?
                .into_iter()
                .map(|s| series(doc, s))
                .collect::<Result<_, _>>()?,
            autospectrum,
            cross: doc
                .list(node, "m_crossSpecInfoList")?
                .into_iter()
                .map(|s| spectrum(doc, s, "m_uSignodeId"))
                .collect::<Result<_, _>>()?,
            at: node.range().start,
        })
    }
}

/// A `TimeSeries`: its values, and a time vector as long as they are.
fn series(doc: &Doc, node: Node) -> Result<Series, FormatError> {
    let values = doc.array(node, "m_ValueVector")?;
    let length: u64 = doc.value(node, "unsigned_int", "m_TimeVector.length")?;
    if length != values.len() as u64 {
        let member = doc.need(node, "unsigned_int", "m_TimeVector.length")?;
        return Err(doc.fail(
            member,
            format!(
                "{length} times for {} values: a time series has one time per value",
                values.len()
            ),
        ));
    }
    Ok(Series {
        values,
        start_s: doc.float(node, "m_TimeVector.start")?,
        end_s: doc.float(node, "m_TimeVector.end")?,
    })
}

/// A `SigNodeCrossSpectrumInfo`: the other signal's node (member `other`), the
/// averaged spectrum and its frequencies, of one length.
fn spectrum(doc: &Doc, info: Node, other: &str) -> Result<Spectrum, FormatError> {
    let cross = doc.need(info, "CrossSpectrum", "m_avgCrossSpec")?;
    let values = doc.array(cross, "m_ValueVector")?;
    let frequency_hz = doc.array(cross, "m_FrequencyVector")?;
    if values.len() != 2 * frequency_hz.len() {
        return Err(doc.fail(
            cross,
            format!(
                "{} spectral values at {} frequencies: one value per frequency",
                values.len() / 2,
                frequency_hz.len()
            ),
        ));
    }
    Ok(Spectrum {
        other: doc.unsigned(info, other)?,
        averaged: doc.unsigned(info, "m_uNumSpectraInAvg")?,
        re: values.iter().step_by(2).copied().collect(),
        im: values.iter().skip(1).step_by(2).copied().collect(),
        frequency_hz,
    })
}
