//! The plan of an identification of several records (`plan` in the result): which
//! record determined which parameter, what was refined jointly, and what no record
//! determines ([`crate::identify::by_record`] makes it).

/// One record's stage: the parameters it determined, the others held.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordStage {
    /// The record (its file).
    pub record: String,
    pub parameters: Vec<String>,
    /// Its own fit's evaluations, wall time, and how it ended.
    pub evaluations: usize,
    pub wall_time_s: f64,
    pub termination: String,
}

/// The plan and how it ran.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordPlan {
    /// The stages in the order they ran (closed-loop simulations first: their
    /// backlash and friction are what a frequency response's nonlinear test takes
    /// as given).
    pub stages: Vec<RecordStage>,
    /// The parameters fitted jointly after the stages, from where they left them:
    /// those whose information other records share, and those coupled to them.
    pub refined: Vec<String>,
    /// The joint refinement's evaluations and how it ended (absent without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refinement: Option<String>,
    /// Parameters no record determines, nor all of them together: held at their
    /// start values, without an interval.
    pub undetermined: Vec<String>,
    /// Per parameter, each record's share of the information about it at the start.
    pub shares: Vec<(String, Vec<(String, f64)>)>,
}
