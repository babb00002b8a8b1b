// gyrocal report: the first script of the page (docs/report.md, "Checks the page makes on itself"). It records
// every error (script errors, failed loads, content-security-policy violations) as a JSON array in
// <body data-js-errors>. Compiled into gyrocal by src/report/embed_file.cmake and inlined into every report.
(function () {
  'use strict';
  var errors = [];
  function record(message) {
    errors.push(String(message));
    document.body.setAttribute('data-js-errors', JSON.stringify(errors));
  }
  window.gyrocalRecordError = record;
  window.addEventListener('error', function (e) {
    if (e.message) record(e.message + (e.lineno ? ' (line ' + e.lineno + ')' : ''));
    else if (e.target && e.target !== window) record('failed to load ' + (e.target.src || e.target.href || e.target.tagName));
    else record('error');
  }, true);
  window.addEventListener('unhandledrejection', function (e) { record('unhandled rejection: ' + e.reason); });
  document.addEventListener('securitypolicyviolation', function (e) {
    record('blocked by the content security policy: ' + e.blockedURI + ' (' + e.violatedDirective + ')');
  });
  document.body.setAttribute('data-js-errors', '[]');
})();
