// One inspected part as a QIF 3.0 (ISO 23952) document, for quality systems
// that import QIF Results (PiWeb, PolyWorks DataLoop, CMM suites) without a
// parser of their own. Input is the part's typed report
// (core/pipeline/inspection_report.h, with its plan); the XML is built with pugixml and validates
// against the QIF 3.0 XSD (QIFApplications/QIFDocument.xsd).
//
// Mapping (millimetres, FileUnits say so):
//   - Product/PartSet/Part: the part type the cell inspects; Results'
//     ActualComponent: this part, SerialNumber = the part id.
//   - MeasurementResources/MeasurementDevice: the cell (Name) and its sensor
//     (Description).
//   - Characteristics in report order: the surface and every region as a
//     SurfaceProfileCharacteristic, every section as a
//     LineProfileCharacteristic whose nominal's Vector is its plane's normal
//     (a SurfaceProfile when the report lacks its "sections" entry), every comparison
//     point as a PointProfileCharacteristic (the QIF type whose Value is a
//     signed deviation at one location); a hole as two, a
//     DiameterCharacteristic and a PositionCharacteristic named "<name>
//     diameter" and "<name> position"; a slot as three, Width, Length and
//     Position ("<name> width", "<name> length", "<name> position").
//     Definition, nominal, item and measurement ids are 10 + 4k .. 13 + 4k
//     for the k-th QIF characteristic, and each item's
//     CharacteristicDesignator carries the name and a name-based UUID, so
//     the same plan gives the same ids in every part.
//   - Tolerance of a profile: ToleranceValue = upper - lower (the zone
//     width); an unequal band adds OuterDisposition = upper (the XSD: "the
//     upper tolerance limit when the tolerance zone is expressed as a
//     bi-directional tolerance"). Of a size: Tolerance with MaxValue =
//     upper, MinValue = lower, DefinedAsLimit false (signed deviations from
//     the nominal). Of a position: ToleranceValue = the zone's diameter,
//     MaterialCondition REGARDLESS, a two-dimensional DiametricalZone (the
//     centre is measured in the hole's plane), and the size's definition as
//     SizeCharacteristicDefinitionId.
//   - Value of a surface profile is the zone width 2 * max(|min|, |max|):
//     the width of the narrowest zone centred on the nominal surface that
//     holds every scanned point, the same quantity as ToleranceValue (QIF's
//     Value is the actual value of the toleranced quantity). The signed
//     extremes go to WorstPositiveDeviation / WorstNegativeDeviation. A
//     point profile's Value is the report's value_mm (mean signed deviation).
//     A size's Value is the measured size, its nominal's TargetValue the
//     measured size minus its deviation; a position's Value is the true
//     position (2 x the centre's distance from nominal). A characteristic
//     without points, or a hole not measured, has no Value (nor TargetValue).
//   - Status PASS/FAIL per characteristic is the report's verdict (which may
//     allow a fraction of points outside the band, so a passing surface can
//     have Value > ToleranceValue); a hole's diameter, length and position
//     each get their own (HoleVerdictsOf, core/report/report_content.h);
//     not measured is INDETERMINATE. InspectionStatus is the part's verdict.
//   - The scanned points stay in the PLY file: MeasurementResults'
//     ExternalFileReference names it (URI relative to the QIF file).
#pragma once

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/pipeline/inspection_report.h"

namespace surfinspect {

struct QifContext {
  std::string part_id;     // this part (ActualComponent SerialNumber); required
  std::string cell;        // the cell's name (MeasurementDevice Name); required
  std::string part_model;  // the part type, e.g. its CAD file name; empty: "part of cell <cell>"
  std::string sensor = "robot-carried 2.5D area sensor";  // MeasurementDevice Description
  std::string points_uri = "errormap.ply";  // scanned points, relative to the QIF file
  std::size_t points_count = 0;             // points in that file
  std::string points_frame = "world";       // the frame of its coordinates
  std::string time_created;                 // xs:dateTime (UTC, "...Z"); empty: omitted
};

// The QIF document's text. InvalidArgument when the report is not a
// surfinspect.report/2 with a pass/fail verdict and well-formed
// characteristics, or the context lacks the part id or the cell.
absl::StatusOr<std::string> QifResultsXml(const InspectionReport& report,
                                          const QifContext& context);

// QifResultsXml written atomically to `path`.
absl::Status WriteQifResults(const std::string& path, const InspectionReport& report,
                             const QifContext& context);

// A name-based UUID (ISO/IEC 9834-8 / RFC 4122 version 5, SHA-1) of `name`
// in surfinspect's namespace, lower-case 8-4-4-4-12.
std::string QifUuid(const std::string& name);

// The current UTC time as xs:dateTime, seconds resolution.
std::string QifTimeNow();

}  // namespace surfinspect
